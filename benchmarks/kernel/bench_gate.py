"""Cost of the gouge gate on a long run, against the path it checks (issue 9).

The issue measured a 70 000-cycle path that peaked at 786 MB and spent 45 of its 53 s in
the gouge check, with no progress shown. This prints, for one closed edge followed with a
step chosen to give about ``--cycles`` cycles: the time to compute the path, the time of
the gate (and its share of the total), the gate's cost per cycle in microseconds, its
progress calls, and the process's peak resident memory. Ratios, not absolute times, are
the figures to compare across machines.

    .venv/bin/python -m benchmarks.kernel.bench_gate [--cycles N] [--case torus_cone]
"""

from __future__ import annotations

import argparse
import resource
import time

import cadcnc
from benchmarks import ROOT
from cadcnc.ops.path.pair_path import intersection_path
from cadcnc.verification import gouge_gate

CASES = {  # fixture, faces, ball radius (mm), edge length (mm)
    "torus_cone": ("torus_cone.step", 1, 2, 3.0, 97.78685),
    "bspline_boss": ("bspline_boss.step", 4, 5, 3.0, 50.658454),
}
PERIOD = 0.004


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def measure(case: str, cycles: int) -> dict:
    """The path and its gate on ``case`` with about ``cycles`` cycles: seconds, cycles,
    progress calls and peak resident memory (MB) before, after the path and the gate."""
    name, i, j, radius, length = CASES[case]
    part = cadcnc.load_step(ROOT / "fixtures" / name)
    step = length / cycles
    feed = 60.0 * step / PERIOD
    base = peak_mb()
    t0 = time.perf_counter()
    tp = intersection_path(part.face(i), part.face(j), radius=radius, feed=feed,
                                  period=PERIOD, max_cycles=10 * cycles)
    t1 = time.perf_counter()
    after_path = peak_mb()
    calls = []
    gate = gouge_gate(tp, part, progress=lambda *a: calls.append(a))
    t2 = time.perf_counter()
    return {"case": case, "faces": (i, j), "radius": radius, "step": step, "feed": feed,
            "cycles": len(tp), "stop": tp.stop_reason, "path_s": t1 - t0, "gate_s": t2 - t1,
            "ok": gate.ok, "depth_mm": gate.depth_mm, "progress": len(calls),
            "stages": sorted({c[2] for c in calls}),
            "peak_mb": (base, after_path, peak_mb())}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cycles", type=int, default=70_000)
    ap.add_argument("--case", choices=sorted(CASES), default="torus_cone")
    args = ap.parse_args()
    m = measure(args.case, args.cycles)
    (i, j), n, path_s, gate_s = m["faces"], m["cycles"], m["path_s"], m["gate_s"]
    print(f"{args.case} faces {i}/{j}, R {m['radius']} mm, step {m['step'] * 1e3:.3f} um "
          f"(feed {m['feed']:.1f} mm/min at {PERIOD * 1e3:g} ms): {n} cycles, "
          f"stop {m['stop']}")
    print(f"path  {path_s:7.2f} s  ({path_s / n * 1e6:7.1f} us/cycle)")
    print(f"gate  {gate_s:7.2f} s  ({gate_s / n * 1e6:7.1f} us/cycle), "
          f"{gate_s / (path_s + gate_s):.0%} of the total; ok={m['ok']}, "
          f"depth {m['depth_mm']:.3g} mm")
    print(f"progress: {m['progress']} calls over stages {', '.join(m['stages'])}")
    base, after_path, after_gate = m["peak_mb"]
    print(f"peak RSS: {base:.0f} MB at start, {after_path:.0f} MB after the path, "
          f"{after_gate:.0f} MB after the gate")


if __name__ == "__main__":
    main()
