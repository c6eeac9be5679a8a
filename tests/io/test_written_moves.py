"""The moves the gate checks are the moves written (issue 24): ``program_written_moves``
computes them without writing the G-code, and gives the very floats that
``segment_moves`` reads back from ``program_ngc``'s text, for every point kept or
dropped, with the tool tip programmed or the ball centre, and signed zeros alike."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import InputError
from cadcnc.core.job import Job, Pencil, Raster, Tool
from cadcnc.io.program_gcode import program_ngc, program_written_moves, segment_moves
from helpers.fixtures import FIXTURES

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def programs():
    slot = cadcnc.load_step(str(FIXTURES / "step_slot.step"))
    boss = cadcnc.load_step(str(FIXTURES / "finish_boss.step"))
    return [cadcnc.run(slot, Job(Tool(3.0, 0.0), 1500.0, 0.004, Pencil(None, "climb"))),
            cadcnc.run(boss, Job(Tool(3.0, 0.0), 1500.0, 0.004,
                                 Raster((6,), 4.0, None, 0.0, "zigzag")))]


@pytest.mark.parametrize("options", [{}, {"tolerance": 0.002}, {"tool_tip": True},
                                     {"tolerance": 0.01, "tool_tip": True, "blend": 0.0005}])
def test_written_moves_are_those_read_back_from_the_text(programs, options):
    for program in programs:
        offset = program.job.tool.radius if options.get("tool_tip") else 0.0
        read = segment_moves(program_ngc(program, **options), offset)
        moves = program_written_moves(program, **options)
        assert len(moves) == len(read) == len(program.segments)
        for a, b in zip(moves, read):
            assert a.shape == b.shape and np.array_equal(a, b)
            assert np.array_equal(np.signbit(a), np.signbit(b))


def test_written_moves_refuse_what_cannot_be_written(programs):
    program = programs[0]
    bad = program.segments[0].points.copy()
    program.segments[0].points[0, 0] = np.nan
    try:
        with pytest.raises(InputError, match="non-finite point"):
            program_written_moves(program)
    finally:
        program.segments[0].points[:] = bad
