"""A run planned more than one way keeps the fastest plan, and a way given up early is
one that could not have won.

- Where the jerk's D v³ term binds the speed (a path whose p''' is large: the corner of
  a B-spline boss on a fast machine), the run is also planned with D_SHARE_HIGH of J for
  that term (more speed, less room for the tangential jerk, a longer window): here that
  plan wins, and the stream stays within every limit by finite differences.
- A plan is given up (``run_plan._Slower``) as soon as one of its rounds lasts as long as
  the plan it is to beat: planned again without giving up, every run's profile is the
  same to the bit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import cadcnc
from cadcnc.controller import Machine, run_plan, stream_program
from cadcnc.controller.feed_plan import plan_feed
from cadcnc.controller.pieces import pieces_of
from cadcnc.ops.finish.shortcut import finish
from cadcnc.ops.path.pair_path import pair_job
from cadcnc.ops.path.pair_program import program_for_job
from cadcnc.ops.stream_steppers import stepper_factory
from helpers.fixtures import FIXTURES

HSM = Machine(0.001, (35_000 / 60,) * 3, (5000.0,) * 3, (50_000.0,) * 3, "high-speed mill")
CUSTOM = Machine(0.0005, (100.0, 80.0, 50.0), (1000.0, 800.0, 500.0),
                 (20_000.0, 16_000.0, 10_000.0), "custom INI-like machine, 0.5 ms")
SLACK = 1e-6


@pytest.fixture(scope="module")
def corner():
    part = cadcnc.load_step(FIXTURES / "bspline_boss.step")
    _, _, job = pair_job(part.face(4), part.face(5), radius=3.0, feed=1500.0, period=0.004)
    return part, program_for_job(part, job)


def _bending(program, machine):
    plan = plan_feed(pieces_of(program, machine, 10_000.0), machine)
    return max((r for r in plan.runs if r.bends), key=lambda r: r.length)


def test_where_d_binds_the_higher_share_is_tried_and_kept_when_faster(corner):
    part, program = corner
    run = _bending(program, HSM)
    V, A, J = run_plan._limits(HSM)
    A = np.minimum(A, np.cbrt(J * J * run.length))
    assert run_plan._d_binds(run, V, J, HSM.period)
    low = run_plan._best_share(run, HSM, (V, A, J))
    high = run_plan._best_share(run, HSM, (V, A, J), run_plan.D_SHARE_HIGH)
    chosen = run_plan.plan_run(run, HSM, measured=False)
    assert high.duration < 0.95 * low.duration   # 0.715 against 0.791 s when written
    assert chosen.duration == min(low.duration, high.duration)
    # the winner's limits where they are, its motion measured: kept only when faster
    assert run_plan.plan_run(run, HSM).duration <= chosen.duration
    stream = stream_program(program, HSM, stepper_factory(part), feed=10_000.0)
    x = stream.positions
    for k, lim in ((1, HSM.max_velocity), (2, HSM.max_acceleration), (3, HSM.max_jerk)):
        share = np.abs(np.diff(x, k, axis=0)) / HSM.period ** k / np.asarray(lim)
        assert share.max() <= 1.0 + SLACK, k


def test_a_straight_run_never_asks_for_the_higher_share():
    p = np.array([[0.0, 0.0, 0.0], [40.0, 0.0, 0.0]])
    from cadcnc.controller.pieces import Piece
    plan = plan_feed([Piece(p, np.array([0.0, 40.0]), 150.0, 0)], HSM)
    V, A, J = run_plan._limits(HSM)
    assert not run_plan._d_binds(plan.runs[0], V, J, HSM.period)


@pytest.mark.parametrize("machine", [HSM, CUSTOM, Machine.default()],
                         ids=["hsm", "custom", "default"])
def test_giving_up_early_changes_no_plan(corner, machine, monkeypatch):
    fillet = finish(cadcnc.load_step(FIXTURES / "finish_fillet.step"), [6, 3], radius=3.0,
                    stepover=10.0)
    plans = [plan_feed(pieces_of(p, machine, 10_000.0), machine)
             for p in (corner[1], fillet)]
    windowed = run_plan._windowed
    monkeypatch.setattr(run_plan, "_windowed", lambda *a, beat=math.inf, **k: windowed(*a, **k))
    for plan in plans:
        for run, profile in zip(plan.runs, plan.profiles):
            again = run_plan.plan_run(run, machine)
            assert again.duration == profile.duration
            assert np.array_equal(again.v, profile.v) and again.window == profile.window
