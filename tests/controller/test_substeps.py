"""Several kernel cycles a period on a cut whose accurate step is shorter than the feed's
step a period: the lengths split, the count chosen, and the stream on a free-form raster
judged from outside (finite differences, the face's offset by OCCT)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from cadcnc.controller import Machine
from cadcnc.controller.cut_rows import substep_lengths
from cadcnc.controller.pieces import MAX_SUBSTEPS, substeps_for
from cadcnc.controller.topp import flatten

UM = 1e-3   # mm
HSM = Machine(0.001, (35_000 / 60,) * 3, (5000.0,) * 3, (50_000.0,) * 3, "high-speed mill")


def test_substep_lengths_split_each_period_equally():
    s = np.array([0.3, 0.5, 0.5, 1.1])
    got = substep_lengths(s, 0.1, 4).reshape(4, 4)
    assert np.array_equal(got[:, -1], s)   # each period ends where the plan says
    edges = np.r_[0.1, s]
    for k in range(4):
        assert np.allclose(np.diff(np.r_[edges[k], got[k]]), (edges[k + 1] - edges[k]) / 4,
                           rtol=0, atol=1e-15)


def test_substeps_are_the_fewest_that_lift_every_cap():
    """A line along X at 100 mm/s (feed) with a cap of 30 mm/s a cycle: 4 cycles; the
    axis's own 50 mm/s binds first on a slower axis: 2; never more than MAX_SUBSTEPS."""
    pts = np.c_[np.linspace(0.0, 10.0, 11), np.zeros(11), np.zeros(11)]
    s = pts[:, 0].copy()
    caps = np.full(11, 30.0)
    assert substeps_for(pts, s, caps, 100.0, HSM) == 4
    slow = Machine(0.001, (50.0, 500.0, 500.0), (5000.0,) * 3, (50_000.0,) * 3, "slow X")
    assert substeps_for(pts, s, caps, 100.0, slow) == 2
    assert substeps_for(pts, s, caps / 100.0, 100.0, HSM) == MAX_SUBSTEPS
    assert substeps_for(pts, s, None, 100.0, HSM) == 1
    assert substeps_for(pts, s, np.full(11, 300.0), 100.0, HSM) == 1


def test_a_turn_flattened_behind_a_long_knot_ends():
    """A turn (knots 0 and 1) found from knot 3, whose windows reach back into the long
    knot 2: its window ends before knot 3, and the sweep must still move on (it flattened
    the same turn forever: a raster planned on a high-speed mill never finished)."""
    s = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    t = np.array([0.0, 0.01, 0.02, 0.1, 0.11])
    w = np.array([0.0, 200.0, 100.0, 100.0, 100.0])
    u = np.array([100.0, -100.0, 0.0, 0.0, 0.0])
    wl = np.full(5, 1e4)
    need = np.array([0.0, 0.0, 0.0, 1.0, 0.0])
    out = []
    worker = threading.Thread(target=lambda: out.append(
        flatten.py_func(s, t, w, u, wl, need, 0.05)), daemon=True)
    worker.start()
    worker.join(10.0)
    assert out == [1]
    assert wl.min() < 1e4   # the turn was flattened


@pytest.mark.slow
def test_a_free_form_raster_on_a_high_speed_mill_steps_several_cycles_a_period():
    """finish_slab's B-spline face, raster R 3, on a high-speed mill (1 ms) at 10 000
    mm/min: one cycle a period would hold its cuts to 90 mm/s; with several the periods go
    further, every limit is kept by finite differences, and every row is within 0.1 µm of
    its pass (the face's offset by OCCT and the pass's plane)."""
    import cadcnc
    from cadcnc.controller import stream_program
    from cadcnc.ops.finish.shortcut import finish
    from cadcnc.ops.stream_steppers import stepper_factory
    from cadcnc.testing.contour_reference import PathReference
    from helpers.fixtures import FIXTURES

    part = cadcnc.load_step(FIXTURES / "finish_slab.step")
    program = finish(part, [5], radius=3.0, stepover=4.0)
    stream = stream_program(program, HSM, stepper_factory(part), feed=10_000.0)
    cuts = [p for p in stream.plan.pieces if p.cut is not None]
    assert max(p.substeps for p in cuts) > 1
    v, a, j = stream.derivatives()
    limits = [HSM.max_velocity, HSM.max_acceleration, HSM.max_jerk]
    for d, lim in zip((v, a, j), limits):
        assert (np.abs(d).max(axis=0) <= np.asarray(lim) * (1.0 + 1e-6)).all()
    speed = np.linalg.norm(v, axis=1)
    assert speed.max() > 1.2 * 0.9 * program.job.step / HSM.period   # past one cycle's cap
    err = PathReference(stream.plan.pieces, program, part).stream_error(stream.positions,
                                                                        stream.rows)
    assert err.max() <= 0.1 * UM
