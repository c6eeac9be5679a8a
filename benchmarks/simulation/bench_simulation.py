"""The stock simulation's speed: a raster program of about 1e5 moves (ball R 3 mm, shank to
the clearance) over a wavy surface, on a 100 x 100 x 50 mm box at 0.05 mm (8e6 rays).
Prints the time per move and per ray, the threads, the K the rays grew to, the memory, and
the time of the stock mesh from the three grids.

    python -m benchmarks.simulation.bench_simulation [--moves N] [--resolution MM] [--jobs N]

The issue's target: 1e5 moves at 0.05 mm in at most 60 s on 2 cores (docs/simulate.md).
"""

from __future__ import annotations

import argparse
import os
import time

import numba
import numpy as np

from cadcnc.simulation.grid import evaluations, rays
from cadcnc.simulation.stock import cut_stock
from cadcnc.simulation.stock_mesh import dexel_mesh, stride_for
from cadcnc.simulation.tool_moves import Run

LO, HI = np.array([0.0, 0.0, 0.0]), np.array([100.0, 100.0, 50.0])
R, CLEARANCE = 3.0, 60.0


def surface(x, y):
    """The finished surface, mm: 36..44 over the box."""
    return 40.0 + 4.0 * np.sin(x / 10.0) * np.cos(y / 13.0)


def raster(moves: int) -> Run:
    """Zigzag passes along X, stepover 0.5 mm, joined at the ends: about ``moves`` moves."""
    passes = 200
    per = max(moves // passes, 2)
    xs = np.linspace(-R, 100 + R, per)
    pts = []
    for k, y in enumerate(np.linspace(0, 100, passes)):
        x = xs if k % 2 == 0 else xs[::-1]
        pts.append(np.stack([x, np.full(per, y), surface(x, y) + R], 1))
    pts = np.concatenate(pts)
    return Run(pts, np.zeros(len(pts) - 1, bool), R, np.array([0.0, 0.0, 1.0]), CLEARANCE)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--moves", type=int, default=100_000)
    ap.add_argument("--resolution", type=float, default=0.05)
    ap.add_argument("--jobs", type=int, default=None)
    args = ap.parse_args(argv)
    load = os.getloadavg()[0]
    run = raster(args.moves)
    warm = Run(run.points[:50], run.rapid[:49], R, run.axis, CLEARANCE)
    cut_stock(LO, HI, 1.0, [warm], jobs=args.jobs)          # compile / load the cache
    clock, cpu = time.perf_counter(), time.process_time()
    stock = cut_stock(LO, HI, args.resolution, [run], jobs=args.jobs)
    seconds, cpu = time.perf_counter() - clock, time.process_time() - cpu
    n, nr = len(stock.moves), rays(LO, HI, args.resolution)
    ev = evaluations(LO, HI, args.resolution, stock.moves.bb_lo, stock.moves.bb_hi)
    mem = sum(g.iv.nbytes + g.cnt.nbytes for g in stock.grids)
    print(f"{n} moves on {nr:.3g} rays ({HI - LO} mm at {args.resolution} mm), "
          f"{numba.get_num_threads()} threads: {seconds:.1f} s ({cpu:.1f} s of CPU; load "
          f"average before {load:.1f})")
    print(f"  per move {seconds / n * 1e6:.0f} us; per ray {seconds / nr * 1e6:.2f} us; per "
          f"ray a move's box covers {seconds / ev * 1e9:.2f} ns ({ev:.3g} of them; "
          f"{cpu / ev * 1e9:.2f} ns of CPU)")
    print(f"  intervals per ray at most {max(g.iv.shape[1] for g in stock.grids)}; "
          f"stock {mem / 1e6:.0f} MB; volume left {stock.volume() / 1e3:.1f} cm^3")
    dexel_mesh(stock, max_side=10)                           # compile / load the cache
    clock = time.perf_counter()
    verts, tris = dexel_mesh(stock)
    print(f"  stock mesh from the three grids: one ray in {stride_for(stock)}, "
          f"{len(tris):.3g} triangles in {time.perf_counter() - clock:.1f} s; load average "
          f"after {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
