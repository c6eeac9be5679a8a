"""Per-cycle overhead of the third-face / shank guard on real parts.

For each concave pair of a part (up to ``--pairs``) whose stretch finder yields a
stretch, runs the stepper along the first stretch (feed 1500 mm/min, period 0.004 s:
0.1 mm steps, R = 3, shank 30 mm) and then calls the guard once per recorded point in
path order, as the stepper would once per cycle. Prints, per pair and overall, the
stepper's own time per cycle and the guard's (median, p99, max, µs), their ratio, and
the exact OCCT distances per cycle. Ratios in the same process are the figures to
compare across machines.

    .venv/bin/python -m benchmarks.kernel.bench_clearance PART.stp [PART.stp ...] [--pairs N]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import cadcnc
from cadcnc.guard import guard_for
from cadcnc.ops.path.pair_path import pair_job, stepper_for
from cadcnc.ops.path.stretch_paths import plan_for_stretch
from cadcnc.ops.path.stretches import pair_stretches

R, FEED, PERIOD = 3.0, 1500.0, 0.004


def one_pair(part, i: int, j: int):
    """(stepper µs per cycle (n,), guard µs per call (n,), exact calls) or None."""
    s1, s2, job = pair_job(part.face(i), part.face(j), radius=R, feed=FEED, period=PERIOD)
    try:
        found = pair_stretches(s1, s2, job)
    except Exception as exc:   # a benchmark reports, it does not stop
        print(f"  pair {i}-{j}: stretch finder failed: {type(exc).__name__}: {exc}")
        return None
    stretches = [st for e in found for st in e.stretches]
    if not stretches:
        return None
    stepper = stepper_for(plan_for_stretch(s1, s2, job, stretches[0]), 200_000, False,
                          check_cycles=False)
    clock = time.perf_counter_ns
    step_ns, points = [], []
    while True:
        t0 = clock()
        dp = stepper.step()
        step_ns.append(clock() - t0)
        if dp is None:
            break
        points.append(stepper.p)
    guard = guard_for(part, (i, j), job)
    guard_ns = []
    for p in points:
        t0 = clock()
        guard.margin(p)
        guard_ns.append(clock() - t0)
    if not points:
        return None
    return np.array(step_ns) / 1e3, np.array(guard_ns) / 1e3, guard.exact_calls


def stats(a: np.ndarray) -> str:
    return (f"median {np.median(a):7.1f}  p99 {np.percentile(a, 99):8.1f}  "
            f"max {a.max():8.1f} µs")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("parts", nargs="+")
    ap.add_argument("--pairs", type=int, default=6)
    args = ap.parse_args()
    for path in args.parts:
        part = cadcnc.load_step(path)
        print(f"{path}: {len(part)} faces")
        all_step, all_guard, exact, cycles = [], [], 0, 0
        done = 0
        for i, j in part.concave_pairs():
            if done >= args.pairs:
                break
            got = one_pair(part, i, j)
            if got is None:
                continue
            done += 1
            step_us, guard_us, n_exact = got
            all_step.append(step_us)
            all_guard.append(guard_us)
            exact += n_exact
            cycles += len(guard_us)
            print(f"  pair {i:3d}-{j:3d}: {len(guard_us):5d} cycles  stepper "
                  f"{np.median(step_us):6.1f} µs  guard {stats(guard_us)}  "
                  f"exact/cycle {n_exact / len(guard_us):.2f}")
        if not all_step:
            print("  no pair with a stretch")
            continue
        s, g = np.concatenate(all_step), np.concatenate(all_guard)
        print(f"  all {done} pairs, {cycles} cycles: stepper {stats(s)}")
        print(f"  {'':27s}guard   {stats(g)}")
        print(f"  guard / stepper (medians) {np.median(g) / np.median(s):.2f}, "
              f"(means) {g.mean() / s.mean():.2f}; exact distances per cycle "
              f"{exact / cycles:.2f}")


if __name__ == "__main__":
    main()
