"""A waterline program streams: each loop's stepper is rebuilt on its horizontal guide
plane (a raster pass's is vertical), and every streamed row of a loop lies at the loop's
height, the stream ending on the program's last point."""

from __future__ import annotations

import numpy as np

import cadcnc
from cadcnc.controller import Machine, stream_program
from cadcnc.ops.finish.shortcut import finish
from cadcnc.ops.stream_steppers import level_of, stepper_factory
from helpers.fixtures import FIXTURES

UM = 1e-3   # mm


def test_a_waterline_program_streams_on_its_levels():
    part = cadcnc.load_step(FIXTURES / "wl_dome.step")
    program = finish(part, [5], radius=3.0, strategy="waterline", stepdown=2.0)
    assert all(level_of(c.path) is not None for c in program.cuts)
    s = stream_program(program, Machine.default(), stepper_factory(part), feed=3000.0)
    assert np.abs(s.positions[-1] - program.segments[-1].points[-1]).max() < 1e-9
    pieces = s.plan.pieces
    for j, pc in enumerate(pieces):
        if pc.cut is None:
            continue
        z = program.cuts[pc.cut].path.points[0, 2]
        rows = s.positions[s.rows == j]
        assert len(rows) and np.abs(rows[:, 2] - z).max() < UM * 1e-3


def test_a_raster_pass_is_not_taken_for_a_level():
    part = cadcnc.load_step(FIXTURES / "finish_slab.step")
    program = finish(part, [5], radius=3.0, stepover=4.0)
    assert all(level_of(c.path) is None for c in program.cuts)



def test_a_streamed_guide_builds_no_trim_grid_and_streams_the_same(monkeypatch):
    """A stream's steppers check no boundary, so their guide planes are whole faces: the
    trim grid reads inside everywhere, with no build and no exact call, and the stream is
    the same bytes as with each guide's trim grid built."""
    from cadcnc.core.trim_labels import INSIDE
    from cadcnc.ops import stream_steppers
    from cadcnc.ops.finish import pass_setup

    part = cadcnc.load_step(FIXTURES / "finish_slab.step")
    program = finish(part, [5], radius=3.0, stepover=8.0)
    guide = stepper_factory(part)(0, program.cuts[0], 0.001).surfaces[1]
    grid = guide.kernel[1]
    assert guide.whole and grid.stats["calls"] == 0 and grid.stats["build_s"] == 0.0
    (u0, u1), (w0, w1) = guide.u_range, guide.w_range
    for u, w in ((u0, w0), (0.5 * (u0 + u1), 0.5 * (w0 + w1)), (u1 + 10.0, w1 + 10.0)):
        assert grid.classify(u, w) == INSIDE
    whole = stream_program(program, Machine.default(), stepper_factory(part), feed=3000.0)
    built = []

    def guide_built(plane, size, job, whole=False):   # the guide's trim grid built
        face = pass_setup.guide_face(plane, size, job)
        built.append(face)
        return face

    monkeypatch.setattr(stream_steppers, "guide_face", guide_built)
    again = stream_program(program, Machine.default(), stepper_factory(part), feed=3000.0)
    assert built and all(f.kernel[1].stats["calls"] > 0 for f in built)
    assert np.array_equal(np.asarray(whole.positions), np.asarray(again.positions))
