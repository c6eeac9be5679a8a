"""A run's plan is not made again for round-off: a window that the plan needs to within
1e-7 of itself is enough, and flattening that shortens the need by less is no progress;
a bending run's window grows by the secant of its measured jerk (the planning cost per
period on a fast machine, issue 35)."""

from __future__ import annotations

import pytest

import cadcnc
from cadcnc.controller import Machine, run_plan
from cadcnc.controller.feed_plan import plan_feed
from cadcnc.controller.pieces import pieces_of
from cadcnc.ops.finish.shortcut import finish
from helpers.fixtures import FIXTURES

HSM = Machine(0.001, (35_000 / 60,) * 3, (5000.0,) * 3, (50_000.0,) * 3, "high-speed mill")


def _counted(monkeypatch) -> list:
    """The plans of the compiled core made from now on: (grid points, need, window, with
    the limits where they are)."""
    calls, plan_once = [], run_plan._plan_once

    def counted(run, *args, tight=False, **kwargs):
        out = plan_once(run, *args, tight=tight, **kwargs)
        calls.append((len(run.s), float(out[-1].max(initial=0.0)), args[5], tight))
        return out

    monkeypatch.setattr(run_plan, "_plan_once", counted)
    return calls


def test_a_straight_cut_on_a_fast_machine_is_planned_in_few_rounds(monkeypatch):
    part = cadcnc.load_step(FIXTURES / "step_block.step")
    program = cadcnc.run(part, cadcnc.Job(cadcnc.Tool(3.0), 1500.0, 0.004, cadcnc.Pencil(),
                                          source=part.source))
    calls = _counted(monkeypatch)
    plan = plan_feed(pieces_of(program, HSM, 40_000.0), HSM)
    # 3 runs (approach, the 34 mm cut, retract); 17 plans before, 4 for the cut's
    # window wasted on a need 1.7e-8 over it
    assert len(plan.pieces) >= 3 and len(calls) <= 8, calls
    assert 0.7 < plan.duration < 0.8


def test_a_bending_run_is_not_flattened_for_round_off(monkeypatch):
    """The finish's R 9 arcs on the fast machine: the program's plan took 133 plans
    before (16 rounds of flattening a call that shortened the need by 2e-12 s each), 43
    with the window grown by the measured share, 34 with its secant; one arc alone, 16
    (counted on one run: a program's count also depends on which runs share a plan); and
    at most 8 more with its limits where they are, its averaged motion measured."""
    part = cadcnc.load_step(FIXTURES / "finish_fillet.step")
    program = finish(part, [6, 3], radius=3.0, stepover=10.0)
    plan = plan_feed(pieces_of(program, HSM, 10_000.0), HSM)
    assert 2.5 < plan.duration < 2.7
    arc = next(r for r in plan.runs if r.bends)
    calls = _counted(monkeypatch)
    run_plan.plan_run(arc, HSM)
    held = [c for c in calls if not c[3]]
    assert len(held) <= 20 and len(calls) - len(held) <= 8, calls


def test_the_secant_lands_where_a_share_of_c_plus_d_over_w_reaches_one():
    c, d = 0.4, 0.08   # the share measured at window W: c + d / W (reaches 1 at 0.1333 s)
    share = lambda w: c + d / w   # noqa: E731
    root = d / (1.0 - c)
    got = run_plan._secant((0.1, share(0.1)), 0.12, share(0.12))
    assert got == pytest.approx(root * run_plan.SECANT_OVER, rel=1e-12)
    assert share(got) < 1.0 < share(0.12)
    # no line to follow: the first window grown, a share that did not fall, or one whose
    # curvature part alone is over 1 (c >= 1: no window serves)
    assert run_plan._secant(None, 0.12, share(0.12)) is None
    assert run_plan._secant((0.1, 1.1), 0.12, 1.2) is None
    assert run_plan._secant((0.1, 1.5), 0.12, 1.45) is None   # c = 1.2
    # nearly there: still at least SECANT_GROWTH longer than the last window
    assert run_plan._secant((0.1, share(0.1)), 0.1333, share(0.1333)) == \
        pytest.approx(0.1333 * run_plan.SECANT_GROWTH, rel=1e-12)
