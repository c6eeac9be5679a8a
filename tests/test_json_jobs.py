"""A program's JSON made on worker processes (issue 24): the same bytes as made here,
with a setup too, its segments cut into ordered runs of similar size."""

from __future__ import annotations

import json

import pytest

import cadcnc
from cadcnc.geometry.setup import setup_part
from cadcnc.io.outputs import render
from cadcnc.io.program_json import RUNS_PER_JOB, _runs
from cadcnc.workers import START_ENV, close
from conftest import FIXTURES


@pytest.mark.parametrize("origin", [None, (5.0, -2.0, 1.0)], ids=["part", "work-zero"])
def test_the_json_made_on_two_processes_is_the_same_bytes(origin, monkeypatch):
    monkeypatch.setenv(START_ENV, "fork")
    job = cadcnc.Job(cadcnc.Tool(3.0), 1500, 0.004, cadcnc.Pencil(), origin=origin)
    part = setup_part(cadcnc.load_step(FIXTURES / "step_slot.step"), job)
    program = cadcnc.run(part, job)
    assert len(program.segments) >= 8
    one = render(program, "p.json", part)
    two = render(program, "p.json", part, jobs=2)
    close()
    assert two == one and ("setup" in json.loads(one)) == (origin is not None)
    runs = _runs(program.segments, 2)
    assert 2 <= len(runs) <= 2 * RUNS_PER_JOB and all(runs)
    assert [s for run in runs for s in run] == list(program.segments)
    assert _runs(program.segments, 1) == [list(program.segments)]
