"""A run's plan is not made again for round-off: a window that the plan needs to within
1e-7 of itself is enough, and flattening that shortens the need by less is no progress
(the planning cost per period on a fast machine, issue 35)."""

from __future__ import annotations

import cadcnc
from cadcnc.controller import Machine, run_plan
from cadcnc.controller.feed_plan import plan_feed
from cadcnc.controller.pieces import pieces_of
from cadcnc.ops.finish.shortcut import finish
from helpers.fixtures import FIXTURES

HSM = Machine(0.001, (35_000 / 60,) * 3, (5000.0,) * 3, (50_000.0,) * 3, "high-speed mill")


def _counted(monkeypatch) -> list:
    """The plans of the compiled core made from now on: (grid points, need, window)."""
    calls, plan_once = [], run_plan._plan_once

    def counted(run, *args):
        out = plan_once(run, *args)
        calls.append((len(run.s), float(out[-1].max(initial=0.0)), args[5]))
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
    """The finish's R 9 arcs on the fast machine: 133 plans before (16 rounds of
    flattening a call that shortened the need by 2e-12 s each), about 45 now."""
    part = cadcnc.load_step(FIXTURES / "finish_fillet.step")
    program = finish(part, [6, 3], radius=3.0, stepover=10.0)
    calls = _counted(monkeypatch)
    plan = plan_feed(pieces_of(program, HSM, 10_000.0), HSM)
    assert len(calls) <= 60, len(calls)
    assert 2.5 < plan.duration < 2.7
