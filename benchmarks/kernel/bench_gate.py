"""Cost of the gouge gate on a long run, against the path it checks (issue 9).

The issue measured a 70 000-cycle path that peaked at 786 MB and spent 45 of its 53 s in
the gouge check, with no progress shown. This prints, for one closed edge followed with a
step chosen to give about ``--cycles`` cycles: the time to compute the path, the time of
the gate (and its share of the total), the gate's cost per cycle in microseconds, its
progress calls, and the process's peak resident memory. Ratios, not absolute times, are
the figures to compare across machines.

    .venv/bin/python benchmarks/bench_gate.py [--cycles N] [--case torus_cone]
"""

from __future__ import annotations

import argparse
import resource
import time
from pathlib import Path

import cadcnc
from cadcnc.verification import gouge_gate

ROOT = Path(__file__).resolve().parents[1]
CASES = {  # fixture, faces, ball radius (mm), edge length (mm)
    "torus_cone": ("torus_cone.step", 1, 2, 3.0, 97.78685),
    "bspline_boss": ("bspline_boss.step", 4, 5, 3.0, 50.658454),
}
PERIOD = 0.004


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cycles", type=int, default=70_000)
    ap.add_argument("--case", choices=sorted(CASES), default="torus_cone")
    args = ap.parse_args()
    name, i, j, radius, length = CASES[args.case]
    part = cadcnc.load_step(ROOT / "fixtures" / name)
    step = length / args.cycles
    feed = 60.0 * step / PERIOD
    base = peak_mb()
    t0 = time.perf_counter()
    tp = cadcnc.intersection_path(part.face(i), part.face(j), radius=radius, feed=feed,
                                  period=PERIOD, max_cycles=10 * args.cycles)
    t1 = time.perf_counter()
    after_path = peak_mb()
    calls = []
    gate = gouge_gate(tp, part, progress=lambda *a: calls.append(a))
    t2 = time.perf_counter()
    path_s, gate_s = t1 - t0, t2 - t1
    print(f"{args.case} faces {i}/{j}, R {radius} mm, step {step * 1e3:.3f} um "
          f"(feed {feed:.1f} mm/min at {PERIOD * 1e3:g} ms): {len(tp)} cycles, "
          f"stop {tp.stop_reason}")
    print(f"path  {path_s:7.2f} s  ({path_s / len(tp) * 1e6:7.1f} us/cycle)")
    print(f"gate  {gate_s:7.2f} s  ({gate_s / len(tp) * 1e6:7.1f} us/cycle), "
          f"{gate_s / (path_s + gate_s):.0%} of the total; ok={gate.ok}, "
          f"depth {gate.depth_mm:.3g} mm")
    stages = sorted({c[0] for c in calls})
    print(f"progress: {len(calls)} calls over stages {', '.join(stages)}")
    print(f"peak RSS: {base:.0f} MB at start, {after_path:.0f} MB after the path, "
          f"{peak_mb():.0f} MB after the gate")


if __name__ == "__main__":
    main()
