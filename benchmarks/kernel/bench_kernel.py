"""The real-time figures of issue 11 for the compiled stepper, ratios taken in one process.

Per fixture pair (ball 3 mm, f = 0.1 mm): per step (``Stepper.step`` from Python, record
off; compiled and the plain-Python reference) against two bare OCCT D2 calls from Python
with their .Coord() calls; per cycle with the loop compiled (``Stepper.run``); the whole
path (``intersection_path``) cold (the faces' caches emptied by ``clear_caches``: trim
classifier, SurfaceData, trim grids and projectors built inside the timed call) and warm
(kept from the previous path on the same faces) against ``GeomAPI_IntSS`` of the two
offset surfaces, best of 15 interleaved runs each, CPU and wall time, with the trim-grid
build separately (``--whole``: only this); latency
p50 / p99 / p99.9 / max over ``--steps`` steps with GC off, measured five ways
(benchmarks/kernel/latency.py: raw, SCHED_FIFO pinned, kernel-only as the minimum of three
lockstep replays, CPU time, and this machine's floor); a landing step against the median
step; memory per cycle
with the record on, and growth over ``--streamed`` cycles with it off. docs/performance.md
records a run. Times are minima or percentiles of perf_counter_ns (wall) or thread_time_ns
(CPU), in microseconds; the latency methods are latency.py's.

    .venv/bin/python -m benchmarks.kernel.bench_kernel [--steps 100000] [--streamed 1000000]
    .venv/bin/python -m benchmarks.kernel.bench_kernel --whole
"""

from __future__ import annotations

import argparse
import gc
import time
import tracemalloc

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.Geom import Geom_OffsetSurface
from OCP.GeomAPI import GeomAPI_IntSS
from OCP.gp import gp_Pnt, gp_Vec

import cadcnc
from benchmarks import ROOT
from benchmarks.kernel.latency import latency, percentiles
from cadcnc.interp.compiled import new_stepper
from cadcnc.ops.path.pair_path import intersection_path, pair_job, plan_path

CASES = [("bspline_boss", 4, 5), ("crossing_cylinders", 1, 2), ("sphere_cylinder", 1, 2),
         ("torus_cone", 1, 2)]
R, FEED, PERIOD = 3.0, 1500.0, 0.004
clock = time.perf_counter_ns
cpu_clock = time.thread_time_ns


def plan_of(name: str, i: int, j: int):
    part = cadcnc.load_step(ROOT / "fixtures" / f"{name}.step")
    s1, s2, job = pair_job(part.face(i), part.face(j), radius=R, feed=FEED, period=PERIOD)
    return part, plan_path(s1, s2, job), job


def stepper(plan, job, compiled=True, record=False, end=True, max_cycles=10**9, guard=None):
    return new_stepper(plan.s1, plan.s2, plan.offsets, plan.start, feed=job.feed,
                   period=job.period, direction=plan.direction,
                   end=plan.end if end else None, closed=plan.closed and end,
                   tol=job.tolerances, check_boundary=plan.check_boundary,
                   compiled=compiled, record=record, max_cycles=max_cycles, guard=guard)


class PlaneGuard:
    """A wall x = c the ball centre must stay ``gap`` before (a linear clearance)."""

    def __init__(self, c: float, gap: float):
        self.c, self.gap = c, gap

    def margin(self, p):
        return self.c - self.gap - p[0], "ball touches the wall"


LANDINGS = [("ramp_wall", 3, 7, None),                   # boundary: a yes/no rule, bisected
            ("pocket", 10, 17, PlaneGuard(5.0123456789, 3.0))]   # collision: regula falsi


def step_times(st, n: int) -> np.ndarray:
    """Per-step times (us) of n steps with GC off (fewer if the path stops)."""
    out = np.empty(n)
    gc.collect()
    gc.disable()
    try:
        k = 0
        while k < n:
            t0 = clock()
            dp = st.step()
            out[k] = clock() - t0
            if dp is None:
                break
            k += 1
    finally:
        gc.enable()
    return out[:k] / 1000.0


def bare_d2(plan, n: int = 20000) -> float:
    """Minimum time (us) of two OCCT D2 calls from Python with their 12 .Coord() calls."""
    adaptors = [BRepAdaptor_Surface(s.topods, True) for s in (plan.s1, plan.s2)]
    uvs = [plan.start.uv1, plan.start.uv2]
    p, v = gp_Pnt(), [gp_Vec() for _ in range(5)]
    best = float("inf")
    for _ in range(n):
        t0 = clock()
        for a, (u, w) in zip(adaptors, uvs):
            a.D2(u, w, p, v[0], v[1], v[2], v[3], v[4])
            p.Coord(), v[0].Coord(), v[1].Coord(), v[2].Coord(), v[4].Coord(), v[3].Coord()
        best = min(best, clock() - t0)
    return best / 1000.0


def int_ss(surfaces) -> dict:
    """{wall, cpu} (us) of one GeomAPI_IntSS of the two surfaces at tolerance 1e-7 (OCCT's
    default precision)."""
    t0, c0 = clock(), cpu_clock()
    inter = GeomAPI_IntSS(surfaces[0], surfaces[1], 1e-7)
    cpu, wall = cpu_clock() - c0, clock() - t0
    assert inter.IsDone() and inter.NbLines() > 0
    return {"wall": wall / 1000.0, "cpu": cpu / 1000.0}


def whole_path(part, i: int, j: int, cold: bool = True) -> dict:
    """One intersection_path: wall and CPU us, the grid builds' share (wall us, cold only),
    points. ``cold``: the faces' caches emptied first (``FaceSurface.clear_caches``: trim
    classifier, SurfaceData, trim grids and point projectors rebuilt inside the timed call,
    as on the first path of a freshly loaded part); warm: kept from the previous path.
    The part's adjacency (its edges classified once per part) is built before, in both."""
    fa, fb = part.face(i), part.face(j)
    if cold:
        for f in (fa, fb):
            f.clear_caches()
    t0, c0 = clock(), cpu_clock()
    tp = intersection_path(fa, fb, radius=R, feed=FEED, period=PERIOD)
    cpu, wall = cpu_clock() - c0, clock() - t0
    grids = sum(f.kernel[1].stats["build_s"] for f in (fa, fb)) * 1e9 if cold else 0.0
    return {"wall": wall / 1000.0, "cpu": cpu / 1000.0, "grids": grids / 1000.0,
            "points": len(tp.points)}


def path_vs_intss(part, i: int, j: int, plan, reps: int = 15) -> tuple[dict, dict, dict]:
    """Best of ``reps`` interleaved runs (each minimum on its own) of the whole path cold
    and warm and of GeomAPI_IntSS of the same two offset surfaces (each face's surface
    offset by its path offset along the outward normal): ({wall, cpu, grids, points} cold,
    the same warm, {wall, cpu}); each figure is its own minimum over the runs."""
    surfaces = [Geom_OffsetSurface(s.geom_surface, s.normal_sign * off)
                for s, off in zip((plan.s1, plan.s2), plan.offsets)]
    whole_path(part, i, j)                                      # warm-up
    best = [{"wall": float("inf"), "cpu": float("inf")} for _ in range(3)]
    for _ in range(reps):
        runs = whole_path(part, i, j), whole_path(part, i, j, cold=False), int_ss(surfaces)
        for b, run in zip(best, runs):
            for key, value in run.items():   # each figure's own minimum
                b[key] = min(b.get(key, float("inf")), value)
    return best[0], best[1], best[2]


def loop_per_cycle(plan, job, cycles: int) -> float:
    st = stepper(plan, job, end=False, max_cycles=cycles)
    t0 = clock()
    st.run()
    return (clock() - t0) / 1000.0 / max(st.cycles, 1)


def landing(plan, job, guard=None, reps: int = 20) -> tuple[float, float, str, int]:
    """(minimum time us of the step that lands on a limit, median step us of the same
    stepper, stop reason, trial cycles of the landing)."""
    best, steps = float("inf"), []
    for _ in range(reps):
        st = stepper(plan, job, guard=guard)
        dp = 0.0
        while dp is not None:
            t0 = clock()
            dp = st.step()
            last = clock() - t0
            if st.stopped:
                break
            steps.append(last)
        best = min(best, last)
    return best / 1000.0, float(np.median(steps)) / 1000.0, st.stop_reason, st.landing_trials


def memory(plan, job, cycles: int, streamed: int) -> tuple[float, float, int]:
    """(bytes per cycle with the record on, traced growth in bytes over ``streamed``
    cycles with it off (Python loop of step()), cycles run)."""
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    st = stepper(plan, job, record=True, end=False, max_cycles=cycles)
    st.run()
    per_cycle = (tracemalloc.get_traced_memory()[0] - base) / st.cycles
    del st
    st = stepper(plan, job, record=False, end=False, max_cycles=streamed)
    for _ in range(1000):
        st.step()
    before = tracemalloc.get_traced_memory()[0]
    while st.step() is not None:
        pass
    growth = tracemalloc.get_traced_memory()[0] - before
    tracemalloc.stop()
    return per_cycle, growth, st.cycles


def exact_calls(fn):
    """(fn(), how many exact trim classifications (FClass2d) it made)."""
    from cadcnc.geometry.trim_grid import TrimGrid
    calls, classify = [0], TrimGrid.classify

    def counted(grid, u, w):
        calls[0] += 1
        return classify(grid, u, w)

    TrimGrid.classify = counted
    try:
        return fn(), calls[0]
    finally:
        TrimGrid.classify = classify


METHODS = {"raw": "wall, normal scheduling", "fifo": "wall, SCHED_FIFO pinned",
           "kernel": "min of 3 lockstep replays, fifo", "cpu": "thread CPU time",
           "machine": "compiled busy loop of the same median, fifo"}


def print_latency(res: dict, steps: int, exact: int) -> None:
    print(f"  latency over {steps} steps, GC off ({exact} exact trim calls in a run):")
    for key, what in METHODS.items():
        us = res[key]
        if us is None:
            print(f"    {key:8s} ({what}): not permitted here")
            continue
        p50, p99, p999, top = percentiles(us)
        print(f"    {key:8s} p50 {p50:6.2f}  p99 {p99:6.2f}  p99.9 {p999:7.2f}  max {top:9.1f} "
              f"us  p99.9/p50 {p999 / p50:5.2f}  ({what})")


def print_whole(cold: dict, warm: dict, ss: dict) -> None:
    """The whole path cold and warm against GeomAPI_IntSS (ms, and the speed-ups)."""
    print(f"  GeomAPI_IntSS of the offset surfaces: CPU {ss['cpu'] / 1000:6.2f} ms, wall "
          f"{ss['wall'] / 1000:6.2f} ms")
    for label, run in (("cold", cold), ("warm", warm)):
        grids = f" (trim grids, min {run['grids'] / 1000:.2f} ms wall)" if run["grids"] else ""
        print(f"  whole path {label} ({run['points']} points): CPU {run['cpu'] / 1000:6.2f} ms"
              f"{grids}, wall {run['wall'] / 1000:6.2f} ms: {ss['cpu'] / run['cpu']:.1f}x "
              f"faster than IntSS (CPU), {ss['wall'] / run['wall']:.1f}x (wall)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--streamed", type=int, default=1_000_000)
    ap.add_argument("--whole", action="store_true",
                    help="only the whole path (cold and warm) against GeomAPI_IntSS")
    args = ap.parse_args()
    for name, i, j in CASES:
        part, plan, job = plan_of(name, i, j)
        stepper(plan, job).run()                                   # warm-up (JIT load)
        if args.whole:
            print(f"{name} faces {i},{j}")
            print_whole(*path_vs_intss(part, i, j, plan))
            continue
        d2 = bare_d2(plan)
        ref = step_times(stepper(plan, job, compiled=False), 2000)
        fast = step_times(stepper(plan, job, end=False), 20000)
        per_cycle = loop_per_cycle(plan, job, 200_000)
        cold, warm, ss = path_vs_intss(part, i, j, plan)
        print(f"{name} faces {i},{j} (f = 0.1 mm)")
        print(f"  two bare OCCT D2 + .Coord() : {d2:6.2f} us (min)")
        print(f"  step, compiled (min / p50)  : {fast.min():6.2f} / {np.median(fast):6.2f} us"
              f"  = {np.median(fast) / d2:.2f}x the two D2")
        print(f"  step, reference (min / p50) : {ref.min():6.2f} / {np.median(ref):6.2f} us"
              f"  ({np.median(ref) / np.median(fast):.1f}x the compiled)")
        print(f"  cycle, loop compiled        : {per_cycle:6.3f} us")
        print_whole(cold, warm, ss)
        _, exact = exact_calls(lambda: step_times(stepper(plan, job, end=False), args.steps))
        res = latency(lambda: stepper(plan, job, end=False), args.steps)
        print_latency(res, len(res["raw"]), exact)
        if name == CASES[0][0]:
            per, growth, n = memory(plan, job, 100_000, args.streamed)
            print(f"  memory: record on {per:.0f} B/cycle (traced, doubling chunks incl.); "
                  f"record off: {growth} B growth over {n} streamed cycles")
    for name, i, j, guard in [] if args.whole else LANDINGS:
        _, plan, job = plan_of(name, i, j)
        land, median, reason, trials = landing(plan, job, guard)
        print(f"landing {name} faces {i},{j}: {reason} in {trials} trial cycles, "
              f"{land:6.1f} us = {land / median:.1f}x the median step ({median:.2f} us)")


if __name__ == "__main__":
    main()
