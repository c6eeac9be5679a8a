"""One Job for every operation: a record per operation, one entry (``cadcnc.run``), a saved
program that reads back as what it was, and one output layout for every command."""

from __future__ import annotations

import csv

import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import InputError
from cadcnc.core.job import Job, PairPath, Pencil, Raster, Tool
from cadcnc.io.outputs import PROGRAM_CSV_COLUMNS
from cadcnc.io.program_json import program_json, read_program
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

_PARTS: dict = {}


def load_fixture(name: str):
    """A fixture STEP file's Part, loaded once per module."""
    if name not in _PARTS:
        _PARTS[name] = cadcnc.load_step(FIXTURES / f"{name}.step")
    return _PARTS[name]

JOBS = {
    "path": ("pocket", Job(Tool(3.0), 1500.0, 0.004, PairPath(faces=(10, 17)),
                           plunge_feed=300.0, spindle=9000.0)),
    "pencil": ("step_block", Job(Tool(3.0), 1500.0, 0.004, Pencil(side="conventional"))),
    "finish": ("finish_slab", Job(Tool(3.0), 1500.0, 0.004, Raster((5,), stepover=4.0))),
}


@pytest.mark.parametrize("kind", sorted(JOBS))
def test_a_saved_program_reads_back_as_its_operation(kind, tmp_path):
    name, job = JOBS[kind]
    part = load_fixture(name)
    program = cadcnc.run(part, job)
    assert program.job == job and program.cuts
    out = tmp_path / "p.json"
    out.write_text(program_json(program))
    back = read_program(out)
    assert back.job == job and type(back.job.operation) is type(job.operation)
    assert [len(c.points) for c in back.cuts] == [len(c.points) for c in program.cuts]


def test_run_gives_the_finishing_shortcuts_program():
    part = load_fixture("finish_slab")
    by_job = cadcnc.run(part, Job(Tool(3.0), 1500.0, 0.004, Raster((5,), stepover=4.0)))
    by_keywords = cadcnc.finish(part, [5], radius=3.0, stepover=4.0)
    assert len(by_job.segments) == len(by_keywords.segments)
    for a, b in zip(by_job.segments, by_keywords.segments):
        np.testing.assert_array_equal(a.points, b.points)


@pytest.mark.parametrize("bad, word", [("job", "job must be a cadcnc.Job"),
                                       ("operation", "operation must be")])
def test_run_names_a_wrong_argument(bad, word):
    part = load_fixture("step_block")
    with pytest.raises(InputError, match=word):
        if bad == "job":
            cadcnc.run(part, {"radius": 3})
        else:
            Job(Tool(3.0), 1500.0, 0.004, "pencil")


def test_path_and_pencil_write_the_same_csv_columns(tmp_path):
    a, b = tmp_path / "path.csv", tmp_path / "pencil.csv"
    cadcnc_cli("path", FIXTURES / "pocket.step", "--faces", "10", "17", "--radius", "3",
               "-o", a, "-q", check=0)
    cadcnc_cli("pencil", FIXTURES / "step_block.step", "--radius", "3", "-o", b, "-q",
               check=0)
    heads = [next(csv.reader(p.open())) for p in (a, b)]
    assert heads[0] == heads[1] == PROGRAM_CSV_COLUMNS


def test_the_job_carries_plunge_feed_and_spindle_into_the_gcode():
    name, job = JOBS["path"]
    from cadcnc.io.program_gcode import program_ngc

    text = program_ngc(cadcnc.run(load_fixture(name), job))
    assert "S9000 M3" in text and "F300" in text and "M5" in text
