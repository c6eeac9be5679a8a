"""A run that bends is also planned with its limits where they are and its averaged motion
measured (velocity, acceleration and jerk), kept where faster; where the run's grid does
not resolve the path (a waterline loop's closing curl), the stream's own check finds it
over a limit and plans again with every limit held over the window's reach.

Limits are checked by finite differences of the streamed positions (no planner code)."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.controller import Machine, stream_program
from cadcnc.controller.feed_plan import plan_feed
from cadcnc.controller.pieces import pieces_of
from cadcnc.ops.finish.shortcut import finish
from cadcnc.ops.stream_steppers import stepper_factory
from helpers.fixtures import FIXTURES

CUSTOM = Machine(0.0005, (100.0, 80.0, 50.0), (1000.0, 800.0, 500.0),
                 (20_000.0, 16_000.0, 10_000.0), "custom INI-like machine, 0.5 ms")


def _over(x: np.ndarray, m: Machine) -> float:
    """The largest |v|, |a| or |j| of the positions over its axis's limit."""
    return max(float((np.abs(np.diff(x, k, axis=0)) / m.period ** k / np.asarray(lim)).max())
               for k, lim in ((1, m.max_velocity), (2, m.max_acceleration),
                              (3, m.max_jerk)))


def test_the_finish_arcs_measured_are_faster_and_within_the_limits():
    """The finish's R 9 quarter arcs on the custom machine at 10 000 mm/min: measured,
    4.046 -> 3.959 s for the program (the straight runs the same), streamed within every
    limit at its first plan."""
    part = cadcnc.load_step(FIXTURES / "finish_fillet.step")
    program = finish(part, [6, 3], radius=3.0, stepover=10.0)
    pieces = pieces_of(program, CUSTOM, 10_000.0)
    measured, held = plan_feed(pieces, CUSTOM), plan_feed(pieces, CUSTOM, measured=False)
    bent = [r.bends for r in measured.runs]
    assert any(bent) and measured.measured and not held.measured
    assert all(p.measured == b for p, b in zip(measured.profiles, bent))
    for p, q, b in zip(measured.profiles, held.profiles, bent):
        assert p.duration < q.duration * (1.0 - 0.05) if b else p.duration == q.duration
    plans = []
    stream = stream_program(program, CUSTOM, stepper_factory(part), feed=10_000.0,
                            on_plan=lambda plan: plans.append(plan.measured))
    assert plans == [True]
    assert _over(stream.positions, CUSTOM) <= 1.0 + 1e-6
    assert stream.cycle_time == pytest.approx(measured.duration, abs=CUSTOM.period)


def test_a_curl_the_grid_does_not_resolve_is_planned_again_with_its_limits_held():
    """The dome's waterline at 3 000 mm/min: one loop ends in a curl (|p''| up to 2.9 /mm)
    whose p''' the run's grid does not resolve; measured there, the stream would jerk Y
    at 5.6x its limit. The check finds it and the second plan holds every limit over the
    reach (the plan this stream had before the measured plans: it then lowers its
    limits twice, as it did), and the stream is within them."""
    part = cadcnc.load_step(FIXTURES / "wl_dome.step")
    program = finish(part, [5], radius=3.0, strategy="waterline", stepdown=2.0)
    machine = Machine.default()
    plans = []
    stream = stream_program(program, machine, stepper_factory(part), feed=3000.0,
                            on_plan=plans.append)
    assert [p.measured for p in plans] == [True, False, False, False]
    assert _over(stream.positions, machine) <= 1.0 + 1e-6
    held = plan_feed(pieces_of(program, machine, 3000.0), machine, measured=False)
    assert plans[1].duration == held.duration
