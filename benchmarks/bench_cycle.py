"""Per-cycle cost of the direct interpolator against a Newton-corrected marching step.

Prints, for two fixtures, the time of one interpolation cycle (median, p99, max, in
microseconds) and of one baseline step run in the same process: predict along n1 x n2,
then Newton on the four contact parameters to 1e-10 mm (cadcnc.interp.tangency.solve_tangency).
Ratios, not absolute times, are the figures to compare across machines. The interpolator
timed here is the default Stepper (the compiled kernel where both faces have compiled data);
benchmarks/bench_kernel.py prints the real-time figures of docs/performance.md.

    .venv/bin/python benchmarks/bench_cycle.py [--cycles N]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import cadcnc
from cadcnc.ops.path.pair_path import pair_job, plan_path
from cadcnc.interp.stepper import Stepper
from cadcnc.interp.tangency import solve_tangency
from cadcnc.tolerances import DEFAULT
from bench_kernel import step_times  # noqa: E402 (a sibling script)

ROOT = Path(__file__).resolve().parents[1]
CASES = [("crossing_cylinders.step", 1, 2), ("bspline_boss.step", 4, 5)]
R, FEED, PERIOD = 3.0, 1500.0, 0.004


def time_interpolator(plan, cycles: int) -> np.ndarray:
    st = Stepper(plan.s1, plan.s2, plan.offsets, plan.start, feed=FEED, period=PERIOD,
                 direction=plan.direction, end=None, closed=False, record=False,
                 max_cycles=cycles)
    return step_times(st, cycles)


def time_newton(plan, cycles: int) -> np.ndarray:
    tol = replace(DEFAULT, start=1e-10)
    f = FEED * PERIOD / 60
    p = np.array(plan.start.p)
    uv1, uv2 = plan.start.uv1, plan.start.uv2
    t_prev = np.array(plan.direction)
    out = np.empty(cycles)
    for k in range(cycles):
        t0 = time.perf_counter_ns()
        n1, n2 = plan.s1.normal(*uv1), plan.s2.normal(*uv2)
        t = np.cross(n1, n2)
        t /= np.linalg.norm(t) * (1 if t @ t_prev >= 0 else -1)
        guess = p + f * t
        tan = solve_tangency(plan.s1, plan.s2, plan.offsets, uv1, uv2, guess, direction=t,
                             tol=tol)
        out[k] = time.perf_counter_ns() - t0
        p, uv1, uv2, t_prev = np.array(tan.p), tan.uv1, tan.uv2, t
    return out / 1000.0


def summary(us: np.ndarray) -> str:
    return (f"median {np.median(us):8.1f} us  p99 {np.percentile(us, 99):8.1f} us  "
            f"max {us.max():8.1f} us  ({len(us)} cycles)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cycles", type=int, default=300)
    args = ap.parse_args()
    for name, i, j in CASES:
        part = cadcnc.load_step(ROOT / "fixtures" / name)
        plan = plan_path(*pair_job(part.face(i), part.face(j), radius=R, feed=FEED, period=PERIOD))
        time_interpolator(plan, 20)  # warm-up (classifier construction, caches)
        direct = time_interpolator(plan, args.cycles)
        newton = time_newton(plan, len(direct))
        print(f"{name} faces {i},{j}  (step {FEED * PERIOD / 60:.3f} mm)")
        print(f"  direct interpolator : {summary(direct)}")
        print(f"  Newton marching     : {summary(newton)}")
        print(f"  ratio Newton/direct : median {np.median(newton) / np.median(direct):.2f}x"
              f"  p99 {np.percentile(newton, 99) / np.percentile(direct, 99):.2f}x")


if __name__ == "__main__":
    main()
