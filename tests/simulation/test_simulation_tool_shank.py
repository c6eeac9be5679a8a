"""`simulate` sweeps a cadcnc program with the shank its own tool has (10 R unless the job
set its length): the shank the program was computed and guarded for, so that the two
verdicts are about the same tool. ``--shank`` replaces it; a G-code program, which names
no tool, keeps its shank up to its highest point. The report says which."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.io.program_json import write_program_json
from cadcnc.simulation.simulator import simulate
from cadcnc.simulation.tool_moves import run_of_gcode, run_of_program
from helpers.fixtures import FIXTURES

R = 3.0


@pytest.fixture(scope="module")
def part():
    return cadcnc.load_step(FIXTURES / "step_block.step")


def _program(part, shank_length=None):
    tool = cadcnc.Tool(R, shank_length=shank_length)
    return cadcnc.run(part, cadcnc.Job(tool, 1500.0, 0.004, cadcnc.Pencil(),
                                       source=part.source))


@pytest.mark.parametrize("shank_length, want", [(None, 10 * R), (12.5, 12.5)])
def test_a_program_is_swept_with_its_own_tools_shank(part, shank_length, want):
    program = _program(part, shank_length)
    assert run_of_program(program).shank == want
    assert run_of_program(program, shank=40.0).shank == 40.0


def test_a_gcode_program_keeps_its_shank_up_to_its_top():
    pts = np.array([[0.0, 0.0, 5.0], [10.0, 0.0, 5.0], [10.0, 0.0, 20.0]])
    run = run_of_gcode(pts, np.array([False, True]), R)
    assert run.shank is None and run.shank_top == 20.0


def test_the_report_names_the_shank(part, tmp_path):
    program = _program(part, 12.5)
    path = tmp_path / "p.json"
    write_program_json(program, path)
    report = simulate(part, [path], resolution=0.5, jobs=1)
    assert report.data["programs"][0]["shank_mm"] == 12.5
    assert "shank 12.5 mm above the ball centre" in report.summary()
