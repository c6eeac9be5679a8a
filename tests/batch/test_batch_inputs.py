"""A batch never writes over one of its inputs (issue 36, finding 2): every output is
checked against every part and the job file before any work, symbolic links and ``..``
resolved; exit 2 naming both."""

from __future__ import annotations

import json
import shutil

from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

STEP = FIXTURES / "step_block.step"


def _job(path, **data) -> None:
    data = {"options": {"radius": 3}, "operations": [{"command": "pencil"}], **data}
    path.write_text(json.dumps(data))


def test_a_part_that_is_another_parts_output_is_refused(tmp_path):
    """The finding: parts x.step and o/x/pencil.ngc (a STEP file), out o, .ngc outputs:
    the first part's G-code overwrote the second part."""
    shutil.copy(STEP, tmp_path / "x.step")
    (tmp_path / "o" / "x").mkdir(parents=True)
    victim = tmp_path / "o" / "x" / "pencil.ngc"
    shutil.copy(STEP, victim)
    jobs = tmp_path / "jobs.json"
    _job(jobs, parts=["x.step", "o/x/pencil.ngc"], out="o", outputs=[".ngc"])
    run = cadcnc_cli("batch", jobs)
    assert run.returncode == 2, (run.returncode, run.stderr)
    assert "pencil.ngc: is an input of this run" in run.stderr, run.stderr
    assert victim.read_bytes() == STEP.read_bytes()
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == ["x"]   # nothing written


def test_the_job_file_is_never_an_output(tmp_path):
    shutil.copy(STEP, tmp_path / "x.step")
    (tmp_path / "o" / "x").mkdir(parents=True)
    jobs = tmp_path / "o" / "x" / "pencil.json"
    _job(jobs, parts=["../../x.step"], out="..", outputs=[".json"])
    before = jobs.read_bytes()
    run = cadcnc_cli("batch", jobs)
    assert run.returncode == 2, (run.returncode, run.stderr)
    assert "is an input of this run" in run.stderr and "pencil.json" in run.stderr
    assert jobs.read_bytes() == before


def test_links_and_dotdot_are_resolved(tmp_path):
    """A part reached through a symbolic link to the output folder is still refused."""
    shutil.copy(STEP, tmp_path / "x.step")
    (tmp_path / "o" / "x").mkdir(parents=True)
    shutil.copy(STEP, tmp_path / "o" / "x" / "pencil.ngc")
    (tmp_path / "parts").symlink_to(tmp_path / "o" / "x")
    jobs = tmp_path / "jobs.json"
    _job(jobs, parts=["x.step", "o/../parts/pencil.ngc"], out="o", outputs=[".ngc"])
    run = cadcnc_cli("batch", jobs)
    assert run.returncode == 2 and "is an input of this run" in run.stderr, run.stderr


def test_a_command_output_over_its_input_is_exit_2_naming_both(tmp_path):
    """Every command: an output that is (a link to) an input is an input error."""
    step = tmp_path / "part.step"
    shutil.copy(STEP, step)
    link = tmp_path / "link.json"
    link.symlink_to(step)
    run = cadcnc_cli("path", step, "--faces", "3", "8", "--radius", "3", "-o", link)
    assert run.returncode == 2, run.stderr
    assert "link.json: is an input of this run" in run.stderr and "part.step" in run.stderr
    assert step.read_bytes() == STEP.read_bytes()
