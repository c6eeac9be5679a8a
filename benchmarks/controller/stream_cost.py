"""Planning + stream cost per servo period, as a ratio to the bare step (same process).

    .venv/bin/python benchmarks/controller/stream_cost.py

Per program: ``plan`` = cutting into pieces, planning every piece and the per-period arc
lengths, per period of the whole stream; ``drive`` = per period of a cut, the stream's
loop driving the kernel (feed override, landing, positions), kernel step included;
``step`` = the same cuts' steppers stepped at the programmed feed from Python, one call
per period (the bare step); ``on top`` = plan + drive - step, per period; ``ratio`` =
(plan + drive) / step. Steppers are built outside the timings. Best of 3 runs.
"""

from __future__ import annotations

import time
from pathlib import Path

import cadcnc
from cadcnc.controller import Machine, stream_program
from cadcnc.controller.feed_plan import plan_feed
from cadcnc.controller.pieces import pieces_of
from cadcnc.controller.stream import _kernel
from cadcnc.ops.finish.finish import finish
from cadcnc.ops.path.pair_path import pair_job
from cadcnc.ops.path.pair_program import program_for_job
from cadcnc.ops.pencil.pencil import pencil
from cadcnc.ops.stream_steppers import stepper_factory

FIXTURES = Path(__file__).resolve().parents[2] / "fixtures"


def programs():
    part = cadcnc.load_step(FIXTURES / "bspline_boss.step")
    _, _, job = pair_job(part.face(4), part.face(5), radius=3.0, feed=1500.0, period=0.004)
    yield "corner bspline_boss 4 5", part, program_for_job(part, job)
    part = cadcnc.load_step(FIXTURES / "step_block.step")
    yield "pencil step_block", part, pencil(part, radius=3.0)
    part = cadcnc.load_step(FIXTURES / "finish_fillet.step")
    yield "finish finish_fillet 6 3", part, finish(part, [6, 3], radius=3.0, stepover=10.0)


def best(fn, runs: int = 3) -> float:
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def bare_steps(program, factory, machine) -> tuple[float, int]:
    """Seconds and periods of every cut's stepper at the programmed feed, step by step."""
    total, periods = 0.0, 0
    for k, seg in enumerate(program.cuts):
        st = factory(k, seg, machine.period)
        if st is None:
            continue
        feed = program.job.feed
        t = time.perf_counter()
        while st.step(feed) is not None:
            pass
        total += time.perf_counter() - t
        periods += st.cycles
    return total, periods


def drive(program, factory, machine, feed) -> tuple[float, int]:
    """Seconds and rows of the stream's kernel loop over every cut (steppers prebuilt)."""
    plan = plan_feed(pieces_of(program, machine, feed), machine)
    rows, s = plan.targets()
    total, n = 0.0, 0
    for j, piece in enumerate(plan.pieces):
        sel = rows == j
        if piece.cut is None or not sel.any():
            continue
        st = factory(piece.cut, program.cuts[piece.cut], machine.period)
        if st is None:
            continue
        t = time.perf_counter()
        _kernel(st, piece, s[sel], machine.period, "bench")
        total += time.perf_counter() - t
        n += int(sel.sum())
    return total, n


def main() -> None:
    machine = Machine.default()
    print(f"machine: {machine.summary()}")
    print(f"{'program':<26} {'feed':>6} {'periods':>8} {'plan us':>8} {'drive us':>9} "
          f"{'step us':>8} {'on top us':>9} {'ratio':>6}")
    for name, part, program in programs():
        factory = stepper_factory(part)
        stream_program(program, machine, factory)   # warm the compiled code
        for feed in (None, 10_000.0):
            n = stream_program(program, machine, factory, feed=feed).periods
            plan = best(lambda: plan_feed(pieces_of(program, machine, feed), machine).targets())
            d_s, d_n = min((drive(program, factory, machine, feed) for _ in range(3)))
            step_s, step_n = min(bare_steps(program, factory, machine) for _ in range(3))
            plan_us, drive_us, step_us = 1e6 * plan / n, 1e6 * d_s / d_n, 1e6 * step_s / step_n
            print(f"{name:<26} {feed or program.job.feed:>6g} {n:>8} {plan_us:>8.2f} "
                  f"{drive_us:>9.2f} {step_us:>8.2f} {plan_us + drive_us - step_us:>9.2f} "
                  f"{(plan_us + drive_us) / step_us:>6.2f}")


if __name__ == "__main__":
    main()
