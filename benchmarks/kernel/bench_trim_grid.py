"""Trim grid (cadcnc.geometry.trim_grid) against OCCT's FClass2d, per face of STEP parts.

For every face of every part given (files, or folders of *.step / *.stp): build time,
memory, the share of random points answered without FClass2d (O(1) share), time per call of
``FaceSurface.classify`` (wrap + FClass2d), ``TrimGrid.classify``, bare
``FClass2d.Perform`` and the numba-compiled ``trim_lookup.lookup`` (all in this process, so
the ratios are the figures to compare), and disagreements between ``TrimGrid.classify`` and
``FaceSurface.classify`` on ``--points`` random points over the face's (u, w) box enlarged by
5 % each side. Surface models (no solid) are read face by face.

    .venv/bin/python -m benchmarks.kernel.bench_trim_grid PARTS... [--points N] [--max-cells N]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
from OCP.gp import gp_Pnt2d
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedMapOfShape

import cadcnc
from cadcnc.core.errors import StepFileError
from cadcnc.geometry.face_surface import FaceSurface
from cadcnc.geometry.trim_grid import CELL_MIXED, TrimGrid, classifier_tolerance
from cadcnc.interp.kernel.trim_lookup import lookup, wrap

try:
    import numba
except ImportError:  # the kernel column is left empty
    numba = None


def faces_of(path: Path) -> list[FaceSurface]:
    """The part's faces; a surface model (no solid) is read with OCCT directly."""
    try:
        return cadcnc.load_step(path).faces
    except StepFileError:
        reader = STEPControl_Reader()
        if reader.ReadFile(str(path)) != IFSelect_RetDone:
            raise
        reader.TransferRoots()
        fmap = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(reader.OneShape(), TopAbs_FACE, fmap)
        return [FaceSurface(TopoDS.Face_s(fmap.FindKey(i)), i)
                for i in range(1, fmap.Extent() + 1)]


def kernel_loop():
    """A compiled loop of wrap + lookup (None without numba):
    (grid args..., window (4,), u (n,), w (n,), out (n,))."""
    if numba is None:
        return None
    one, into = lookup, wrap  # compiled already (cadcnc.core.trim_labels)

    @numba.njit
    def run(grid, fine, u0, w0, du, dw, nu, nw, window, us, ws, out):
        for k in range(us.shape[0]):
            u, w = into(us[k], window[0], window[1]), into(ws[k], window[2], window[3])
            out[k] = one(grid, fine, u0, w0, du, dw, nu, nw, u, w)

    return run


def timed(fn, points) -> tuple[list, float]:
    """Results of ``fn(u, w)`` over the points and the mean time per call, s."""
    t0 = time.perf_counter()
    out = [fn(u, w) for u, w in points]
    return out, (time.perf_counter() - t0) / len(points)


def measure(face: FaceSurface, n: int, max_cells: int, rng, run) -> dict:
    """One face's figures (times in s)."""
    face.classify(*face.wrap(face.u_range[0], face.w_range[0]))  # build its FClass2d first
    grid = TrimGrid.build(face, max_cells=max_cells)
    (u0, u1), (w0, w1) = face.u_range, face.w_range
    us = rng.uniform(u0 - 0.05 * (u1 - u0), u1 + 0.05 * (u1 - u0), n)
    ws = rng.uniform(w0 - 0.05 * (w1 - w0), w1 + 0.05 * (w1 - w0), n)
    points = list(zip(us.tolist(), ws.tolist()))
    exact, t_face = timed(face.classify, points)
    fast, t_grid = timed(grid.classify, points)
    wrapped = [face.wrap(u, w) for u, w in points]
    fc = BRepTopAdaptor_FClass2d(face.topods, classifier_tolerance(face))
    _, t_perform = timed(lambda u, w: fc.Perform(gp_Pnt2d(u, w)), wrapped)
    codes = np.array([grid.cell(*grid.to_window(u, w)) for u, w in points])
    t_kernel = float("nan")
    if run is not None:
        window, out = np.array(grid.window), np.empty(n, dtype=np.int64)
        run(*grid.kernel_args, window, us[:2], ws[:2], out[:2])  # compile outside the clock
        t0 = time.perf_counter()
        run(*grid.kernel_args, window, us, ws, out)
        t_kernel = (time.perf_counter() - t0) / n
        assert np.array_equal(out, codes), "kernel lookup and TrimGrid.cell disagree"
    return {"face": face.number, "kind": face.kind, "cells": grid.labels.size,
            "build": grid.stats["build_s"], "bytes": grid.labels.nbytes * 2 + grid.codes.nbytes + grid.fine.nbytes,
            "o1": float(np.mean(codes != CELL_MIXED)), "t_face": t_face, "t_grid": t_grid,
            "t_perform": t_perform, "t_kernel": t_kernel,
            "disagree": sum(a != b for a, b in zip(exact, fast)),
            "suspect": grid.stats["suspect"], "exact_only": grid.stats["exact_only"]}


def summary(name: str, rows: list[dict]) -> str:
    """One table line for a part."""
    col = {k: np.array([r[k] for r in rows], dtype=float) for k in rows[0] if k != "kind"}
    tf, tg = col["t_face"].mean() * 1e6, col["t_grid"].mean() * 1e6
    tp, tk = col["t_perform"].mean() * 1e6, col["t_kernel"].mean() * 1e6
    return (f"{name[:32]:32s} {len(rows):5d} {int(col['exact_only'].sum()):4d} "
            f"{np.median(col['build']) * 1e3:7.1f} {col['build'].max() * 1e3:7.1f} "
            f"{col['bytes'].mean() / 1024:6.0f} {np.median(col['o1']) * 100:6.1f} "
            f"{col['o1'].min() * 100:6.1f} {col['o1'].mean() * 100:6.1f} {tf:6.2f} {tg:6.2f} "
            f"{tf / tg:5.1f} {tp:6.2f} {tk:7.3f} {tp / tk:6.0f} "
            f"{int(col['disagree'].sum()):5d} {int(col['suspect'].sum()):4d}")


HEADER = (f"{'part':32s} {'faces':>5s} {'exO':>4s} {'bld_md':>7s} {'bld_mx':>7s} "
          f"{'KiB':>6s} {'O1_md':>6s} {'O1_mn':>6s} {'O1_av':>6s} {'face':>6s} {'grid':>6s} "
          f"{'ratio':>5s} {'Perf':>6s} {'kernel':>7s} {'ratio':>6s} {'disag':>5s} {'susp':>4s}")
LEGEND = """bld_md/bld_mx: build ms, median/max over faces; KiB: mean label memory per face;
O1_*: % of points answered without FClass2d (median/min/mean over faces); face, grid:
FaceSurface.classify and TrimGrid.classify, us per call; Perf: bare FClass2d.Perform (us);
kernel: numba wrap + lookup (us); ratios face/grid, Perf/kernel; disag: disagreements with
FaceSurface.classify; susp: regions left MIXED by the build's cross-check; exO: faces
classified by FClass2d only."""


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("parts", nargs="+", type=Path)
    ap.add_argument("--points", type=int, default=10_000)
    ap.add_argument("--max-cells", type=int, default=4096)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    files = sorted(f for p in args.parts for f in (
        [p] if p.is_file() else [*p.glob("*.step"), *p.glob("*.stp")]))
    rng, run = np.random.default_rng(args.seed), kernel_loop()
    print(HEADER)
    every = []
    for path in files:
        rows = [measure(f, args.points, args.max_cells, rng, run) for f in faces_of(path)]
        every += [(path.name, r) for r in rows]
        print(summary(path.name, rows), flush=True)
    print(summary("ALL", [r for _, r in every]))
    print(LEGEND)
    print("lowest O(1) shares:")
    for name, r in sorted(every, key=lambda x: x[1]["o1"])[:8]:
        print(f"  {name} face {r['face']} ({r['kind']}): {r['o1'] * 100:.1f} %, "
              f"{r['cells']} cells, build {r['build'] * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
