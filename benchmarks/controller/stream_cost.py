"""Planning + stream cost per servo period, as a ratio to the bare step (same process).

    python -m benchmarks.controller.stream_cost [--long | --hsm | --free-form]

Per program and feed, µs per period (best of 5, interleaved; steppers built outside
every timing):

- ``plan``: cutting into pieces, planning every piece and the per-period arc lengths, per
  period of the whole stream;
- ``drive``: per period of a cut, the stream's plan for the kernel (``follow_plan``) and
  the kernel following it (``interp.planned_follow``: the compiled loop, kernel step included);
- ``step``: the bare step, the same cuts' steppers run at the programmed feed in the
  compiled loop (``Stepper.run``), per cycle;
- ``on top`` = plan + drive - step; ``ratio`` = (plan + drive) / step;
- ``stream``: ``stream_program`` end to end (plan, kernel, links, landing), per period
  of the whole stream (links need no step: lower than plan + drive);
- ``py step``: the bare step from Python, one ``step(feed)`` call per period (for scale).

``--long``: one stream of about 1e6 periods (the corner at a crawl): its time per period
and its peak memory per period, then the same for its gate (what ``cadcnc stream`` checks
before writing).

``--hsm``: the high-speed mill (``compare.high_speed_mill``, 1 ms) at 1 500, 10 000 and
40 000 mm/min, where a cut may take m kernel cycles a period: ``plan`` (as above),
``stream`` per period,
``m`` the kernel's cycles per period over the whole stream, and ``on top`` = stream - m
step (the stream's own planning and streaming beside its kernel cycles): the median over
the runs of each run's stream and bare steps measured back to back (a slow spell of a
shared machine then slows both; the best of such differences can go below zero, the
median does not), ``stream`` and ``step`` each the best run.

``--free-form``: the same columns for the race's long
free-form programs (the slab's raster and waterline, ``compare.long_programs``: 60 000 to
180 000 periods, 50 to 70 runs that bend) on the default machine and the high-speed mill
at 10 000 mm/min, best of 3.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import cadcnc
from cadcnc.controller import Machine, stream_program
from cadcnc.controller.cut_rows import LANDING, follow_plan
from cadcnc.controller.feed_plan import plan_feed
from cadcnc.controller.pieces import pieces_of
from cadcnc.core.tolerances import DEFAULT
from cadcnc.interp.planned_follow import follow
from cadcnc.ops.finish.shortcut import finish
from cadcnc.ops.path.pair_path import pair_job
from cadcnc.ops.path.pair_program import program_for_job
from cadcnc.ops.stream_steppers import stepper_factory
from cadcnc.verification import gate_program

FIXTURES = Path(__file__).resolve().parents[2] / "fixtures"


def programs():
    part = cadcnc.load_step(FIXTURES / "bspline_boss.step")
    _, _, job = pair_job(part.face(4), part.face(5), radius=3.0, feed=1500.0, period=0.004)
    yield "corner bspline_boss 4 5", part, program_for_job(part, job)
    part = cadcnc.load_step(FIXTURES / "step_block.step")
    yield "pencil step_block", part, cadcnc.run(part, cadcnc.Job(
        cadcnc.Tool(3.0), 1500.0, 0.004, cadcnc.Pencil(), source=part.source))
    part = cadcnc.load_step(FIXTURES / "finish_fillet.step")
    yield "finish finish_fillet 6 3", part, finish(part, [6, 3], radius=3.0, stepover=10.0)


RUNS = 5   # interleaved: drive, step, py step, stream; the best of each


def best(fn, runs: int = RUNS) -> float:
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def steppers(program, factory, machine) -> list:
    """A fresh stepper per cut (None where a cut has none)."""
    return [factory(k, seg, machine.period) for k, seg in enumerate(program.cuts)]


def bare_steps(program, factory, machine, python: bool = False) -> tuple[float, int]:
    """Seconds and periods of every cut's stepper at the programmed feed: in the compiled
    loop (``run``), or from Python one ``step`` call per period."""
    total, periods = 0.0, 0
    for st in steppers(program, factory, machine):
        if st is None:
            continue
        feed = program.job.feed
        t = time.perf_counter()
        if python:
            while st.step(feed) is not None:
                pass
        else:
            st.run()
        total += time.perf_counter() - t
        periods += st.cycles
    return total, periods


def drive(program, factory, machine, feed) -> tuple[float, int]:
    """Seconds and rows of the kernel following the plan over every cut."""
    plan = plan_feed(pieces_of(program, machine, feed), machine)
    rows, s = plan.targets()
    built = steppers(program, factory, machine)
    total, n = 0.0, 0
    for j, piece in enumerate(plan.pieces):
        sel = rows == j
        st = None if piece.cut is None else built[piece.cut]
        if st is None or not sel.any():
            continue
        t = time.perf_counter()
        follow(st, follow_plan(piece, s[sel]), piece.points[-1], float(piece.kappa[-1]),
               LANDING)
        total += time.perf_counter() - t
        n += int(sel.sum())
    return total, n


def whole(program, factory, machine, feed) -> float:
    """Seconds of stream_program with the steppers prebuilt (a replan, which runs every
    cut again, builds fresh ones: their building is not counted)."""
    built = steppers(program, factory, machine)
    used, extra = set(), [0.0]

    def prebuilt(k, seg, period):
        if k not in used:
            used.add(k)
            return built[k]
        t0 = time.perf_counter()
        fresh = factory(k, seg, period)
        extra[0] += time.perf_counter() - t0
        return fresh

    t = time.perf_counter()
    stream_program(program, machine, prebuilt, feed=feed)
    return time.perf_counter() - t - extra[0]


def _measured(fn):
    """(fn(), wall seconds, peak memory in bytes by tracemalloc: numpy's arrays included)."""
    import tracemalloc

    tracemalloc.start()
    t = time.perf_counter()
    out = fn()
    seconds = time.perf_counter() - t
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return out, seconds, peak


def long_stream(periods: int = 1_000_000) -> None:
    """The corner at the feed that makes its stream ``periods`` long: time per period and
    the peak memory the stream takes, per period; then the same for its gate."""
    machine = Machine.default()
    name, part, program = next(iter(programs()))
    factory = stepper_factory(part)
    length = program.cut_length + sum(s.feed_length for s in program.links)
    feed = 60.0 * length / (periods * machine.period)
    stream, seconds, peak = _measured(
        lambda: stream_program(program, machine, factory, feed=feed))
    n = stream.periods
    print(f"long stream: {name} at F {feed:.3g}: {n} periods in {seconds:.1f} s "
          f"({1e6 * seconds / n:.2f} us per period), peak memory {peak / 1e6:.0f} MB "
          f"({peak / n:.0f} bytes per period; the positions alone take 24)")
    moves = stream.segment_moves(program)   # what `cadcnc stream` gates before writing
    gate, seconds, peak = _measured(lambda: gate_program(program, part, DEFAULT, moves=moves))
    print(f"its gate: {'passed' if gate.ok else 'refused'} in {seconds:.1f} s "
          f"({1e6 * seconds / n:.1f} us per period), peak memory {peak / 1e6:.0f} MB "
          f"({peak / n:.0f} bytes per period)")


def warmed(machine: Machine, columns: str, cases=None):
    """Print the machine and the table's header; yield (name, program, stepper factory)
    of every case (default: :func:`programs`), its compiled code warmed by one stream."""
    print(f"machine: {machine.summary()}")
    print(columns)
    for name, part, program in programs() if cases is None else cases:
        factory = stepper_factory(part)
        stream_program(program, machine, factory)
        yield name, program, factory


def main() -> None:
    machine = Machine.default()
    for name, program, factory in warmed(machine, (
            f"{'program':<26} {'feed':>6} {'periods':>8} {'plan':>6} {'drive':>6} "
            f"{'step':>6} {'on top':>7} {'ratio':>6} {'stream':>7} {'py step':>8}   "
            "(us per period)")):
        for feed in (None, 10_000.0):
            n = stream_program(program, machine, factory, feed=feed).periods
            plan = best(lambda: sum(len(s) for _, _, s in plan_feed(
                pieces_of(program, machine, feed), machine).blocks()), RUNS)
            runs = [(drive(program, factory, machine, feed), bare_steps(program, factory, machine),
                     bare_steps(program, factory, machine, True),
                     whole(program, factory, machine, feed)) for _ in range(RUNS)]
            (d_s, d_n), (step_s, step_n), (py_s, py_n) = (min(r[i] for r in runs)
                                                          for i in range(3))
            w = min(r[3] for r in runs)
            plan_us, drive_us, step_us = 1e6 * plan / n, 1e6 * d_s / d_n, 1e6 * step_s / step_n
            print(f"{name:<26} {feed or program.job.feed:>6g} {n:>8} {plan_us:>6.2f} "
                  f"{drive_us:>6.2f} {step_us:>6.2f} {plan_us + drive_us - step_us:>7.2f} "
                  f"{(plan_us + drive_us) / step_us:>6.2f} {1e6 * w / n:>7.2f} "
                  f"{1e6 * py_s / py_n:>8.2f}")


def kernel_cycles(program, machine, feed) -> tuple[int, int]:
    """(periods, kernel cycles) of the stream: each cut's periods times its substeps."""
    plan = plan_feed(pieces_of(program, machine, feed), machine)
    rows, _ = plan.targets()
    cycles = sum(int((rows == j).sum()) * piece.substeps
                 for j, piece in enumerate(plan.pieces) if piece.cut is not None)
    return len(rows), cycles


def _on_top(machine: Machine, cases, feeds, runs: int = RUNS) -> None:
    """Per case and feed: the plan alone and the whole stream per period, the kernel's
    cycles a period (m), the bare step per cycle and the stream on top of m steps."""
    for name, program, factory in warmed(machine, (
            f"{'program':<26} {'feed':>6} {'periods':>8} {'m':>5} {'plan':>6} {'stream':>7} "
            f"{'step':>6} {'on top':>7}   (us per period; step per cycle)"), cases):
        for feed in feeds:
            n = stream_program(program, machine, factory, feed=feed).periods
            plan = best(lambda: sum(len(s) for _, _, s in plan_feed(
                pieces_of(program, machine, feed), machine).blocks()), runs)
            periods, cycles = kernel_cycles(program, machine, feed)
            m = cycles / periods
            pairs = []   # (stream, step) us measured back to back: a slow spell hits both
            for _ in range(runs):
                w = whole(program, factory, machine, feed)
                step_s, step_n = bare_steps(program, factory, machine)
                pairs.append((1e6 * w / n, 1e6 * step_s / step_n))
            stream_us, step_us = (min(p[i] for p in pairs) for i in range(2))
            top = float(np.median([a - m * b for a, b in pairs]))
            print(f"{name[:26]:<26} {feed:>6g} {n:>8} {m:>5.2f} {1e6 * plan / n:>6.2f} "
                  f"{stream_us:>7.2f} {step_us:>6.2f} {top:>7.2f}", flush=True)


def fast_machine() -> None:
    """The stream's cost per period on the high-speed mill (``--hsm``, module doc)."""
    from benchmarks.controller.compare import high_speed_mill

    _on_top(high_speed_mill(), programs(), (1500.0, 10_000.0, 40_000.0), runs=9)


def free_form() -> None:
    """The long free-form programs of the race (``--free-form``, module doc) at
    10 000 mm/min on the default machine and the high-speed mill."""
    import tempfile

    from benchmarks.controller.compare import high_speed_mill, long_programs

    with tempfile.TemporaryDirectory() as folder:
        cases = list(long_programs(Path(folder), None))
        for machine in (Machine.default(), high_speed_mill()):
            _on_top(machine, cases, (10_000.0,), runs=3)


if __name__ == "__main__":
    import sys

    long_stream() if "--long" in sys.argv else fast_machine() if "--hsm" in sys.argv \
        else free_form() if "--free-form" in sys.argv else main()
