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
