"""A program's outputs made on worker processes (issue 24): the same bytes as made here,
with a setup too; a JSON in ordered runs of segments of similar size, every other output
whole beside them."""

from __future__ import annotations

import json

import pytest

import cadcnc
from cadcnc.core.errors import OutputError
from cadcnc.geometry.setup import setup_part
from cadcnc.io.gcode import blend_for
from cadcnc.io.outputs import render, render_all
from cadcnc.io.program_json import RUNS_PER_JOB, _runs
from cadcnc.parallel.pool import START_ENV, kept_pools
from cadcnc.pipeline import operate as operate_module
from cadcnc.pipeline.operate import Settings, operate, rendered
from helpers.fixtures import FIXTURES


@pytest.fixture(scope="module")
def programs():
    """{origin: (part, program)}: step_slot's pencil R 3, in part coordinates and with a
    work zero (a setup)."""
    out = {}
    for origin in (None, (5.0, -2.0, 1.0)):
        job = cadcnc.Job(cadcnc.Tool(3.0), 1500, 0.004, cadcnc.Pencil(), origin=origin)
        part = setup_part(cadcnc.load_step(FIXTURES / "step_slot.step"), job)
        out[origin] = (part, cadcnc.run(part, job))
    return out


@pytest.mark.parametrize("origin", [None, (5.0, -2.0, 1.0)], ids=["part", "work-zero"])
def test_the_json_made_on_two_processes_is_the_same_bytes(origin, programs, monkeypatch):
    monkeypatch.setenv(START_ENV, "fork")
    part, program = programs[origin]
    assert len(program.segments) >= 8
    one = render(program, "p.json", part)
    two = render_all(program, ["p.json"], part, jobs=2)["p.json"]
    assert two == one and ("setup" in json.loads(one)) == (origin is not None)
    runs = _runs(program.segments, 2)
    assert 2 <= len(runs) <= 2 * RUNS_PER_JOB and all(runs)
    assert [s for run in runs for s in run] == list(program.segments)
    assert _runs(program.segments, 1) == [list(program.segments)]


def test_every_output_made_on_two_processes_is_the_same_bytes(programs, monkeypatch):
    monkeypatch.setenv(START_ENV, "fork")
    part, program = programs[(5.0, -2.0, 1.0)]
    outs = ["p.json", "p.ngc", "p.csv", "p.png", "q.json"]
    gcode = dict(blend=blend_for(program.job.tolerances.gouge))
    one = render_all(program, outs, part, "slot", **gcode)
    two = render_all(program, outs, part, "slot", 2, **gcode)
    assert list(two) == outs and two == one
    assert one["p.ngc"] == render(program, "p.ngc", part, "slot", **gcode)
    with pytest.raises(OutputError, match="unknown output format"):
        render_all(program, ["p.json", "p.txt"], part, "slot", 2)


def test_outputs_rendered_beside_the_gate_are_those_written_after_it(tmp_path, monkeypatch):
    """``operate`` given the outputs at two processes renders them on the workers while
    it gates (``Outcome.contents``): the bytes ``render_all`` makes of the judged program
    afterwards, which ``rendered`` then hands back without rendering again; at one
    process nothing is made ahead."""
    monkeypatch.setenv(START_ENV, "fork")
    step = FIXTURES / "step_slot.step"
    job = cadcnc.Job(cadcnc.Tool(3.0), 1500, 0.004, cadcnc.Pencil(), source=str(step))
    outs = [str(tmp_path / "p.json"), str(tmp_path / "p.ngc")]
    gcode = dict(blend=blend_for(job.tolerances.gouge), tolerance=None, tool_tip=False)
    two = Settings(gcode=gcode, processes=2)
    with kept_pools():
        done = operate(step, job, "pencil", two, outputs=outs)
        assert done.verdict.write and done.contents is not None and list(done.contents) == outs
        again = render_all(done.program, outs, done.part, f"pencil R 3 of {step.name}",
                           **gcode)
        assert done.contents == again
        assert rendered(done, outs, done.what, two) is done.contents
    one = operate(step, job, "pencil", Settings(gcode=gcode, processes=1), outputs=outs)
    assert one.contents is None and rendered(one, outs, one.what, two) == again


def _unmakeable(part, task, beat=None):
    raise OutputError("this output cannot be made")


def test_an_output_failing_ahead_of_the_verdict_does_not_pre_empt_it(tmp_path, monkeypatch):
    """An output made beside the gate that fails (here every worker's piece) is not
    raised there: ``operate`` returns its verdict with no contents, and the outputs are
    made again, by ``rendered``, only when the verdict writes them: the gate's exit code
    comes first, as at one process."""
    monkeypatch.setenv(START_ENV, "fork")
    monkeypatch.setattr(operate_module, "render_piece", _unmakeable)   # the forks inherit it
    step = FIXTURES / "step_slot.step"
    job = cadcnc.Job(cadcnc.Tool(3.0), 1500, 0.004, cadcnc.Pencil(), source=str(step))
    outs = [str(tmp_path / "p.json"), str(tmp_path / "p.ngc")]
    two = Settings(gcode=dict(blend=blend_for(job.tolerances.gouge)), processes=2)
    with kept_pools():
        done = operate(step, job, "pencil", two, outputs=outs)
    assert done.verdict.write and done.contents is None
    assert set(rendered(done, outs, done.what, two)) == set(outs)


def test_the_json_made_a_segment_at_a_time_is_the_whole_programs_text(programs):
    """One process makes the segments' text one at a time, the collector held off: the
    same bytes as the whole program made into Python objects and dumped at once, and the
    collector's state left as it was."""
    import gc

    from cadcnc.io.program_json import program_json, program_to_dict

    part, program = programs[None]
    whole = json.dumps(program_to_dict(program), separators=(",", ":")) + "\n"
    assert gc.isenabled()
    assert program_json(program) == whole
    assert gc.isenabled()
    gc.disable()
    try:
        assert program_json(program) == whole
        assert not gc.isenabled()
    finally:
        gc.enable()


def test_the_console_program_freezes_its_imports_and_collects_after(capsys):
    """The console program (``ending``): what the library's imports made frozen, the
    collector on again for the command (in this process: unfrozen after)."""
    import gc

    from cadcnc.cli.app import main

    assert gc.isenabled()
    try:
        assert main(["faces", str(FIXTURES / "step_block.step")], ending=True) == 0
        assert gc.isenabled() and gc.get_freeze_count() > 10_000
    finally:
        gc.unfreeze()
