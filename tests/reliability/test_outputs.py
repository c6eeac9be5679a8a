"""A failed or interrupted run leaves no half file and never destroys an earlier good one.

Every destination is checked before anything is computed; the set is written to
temporary files and renamed only when all are ready, Ctrl-C deferred during the renames.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

pytestmark = pytest.mark.slow  # subprocesses interrupted mid-write: about 20 s of the fast tier

BOSS = FIXTURES / "bspline_boss.step"
POCKET = FIXTURES / "pocket.step"  # faces 10 17: a straight edge, a program in ~0.2 s
SLOT = FIXTURES / "narrow_slot.step"
JOB = ["--radius", "3", "--feed", "1500", "--period", "4ms"]


def one_line(run, code, *needles):
    assert run.returncode == code, (run.returncode, run.stderr)
    assert "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1
    for needle in needles:
        assert needle in run.stderr, run.stderr


def test_unwritable_second_output_leaves_the_first_untouched(tmp_path, monkeypatch):
    (tmp_path / "ro").mkdir()
    good = tmp_path / "a.json"
    good.write_text("old")
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda p, mode: False if str(p).endswith("ro")
                        else real_access(p, mode))
    run = cadcnc_cli("path", BOSS, "--faces", "4", "5", *JOB, "-o", good,
                     "-o", tmp_path / "ro" / "o.json")
    one_line(run, 4, "not writable")
    assert good.read_text() == "old"


def test_demo_with_a_folder_in_the_way_replaces_nothing(tmp_path):
    out = tmp_path / "demo"
    out.mkdir()
    (out / "path.png").mkdir()
    (out / "path.json").write_text("old")
    run = cadcnc_cli("demo", "--out", out)
    one_line(run, 4, "path.png: is a folder")
    assert (out / "path.json").read_text() == "old"
    assert sorted(p.name for p in out.iterdir()) == ["path.json", "path.png"]


def test_an_output_never_overwrites_the_input(tmp_path):
    """A program written beside its input leaves the input alone; an output that is (a link
    to) the input is refused. The pocket's straight edge: any part shows this."""
    step = tmp_path / "part.step"
    step.write_bytes(POCKET.read_bytes())
    link = tmp_path / "link.json"
    link.symlink_to(step)
    for out in (step, link):
        before = step.read_bytes()
        run = cadcnc_cli("path", step, "--faces", "10", "17", *JOB, "-o", out.with_suffix(
            ".json") if out == step else out)
        if out == step:
            assert run.returncode == 0, run.stderr
        else:
            one_line(run, 2, "input of this run")
        assert step.read_bytes() == before


def test_output_equal_to_input_json_is_refused(tmp_path, boss_program):
    saved = tmp_path / "p.json"
    saved.write_text(boss_program)
    before = saved.read_bytes()
    one_line(cadcnc_cli("plot", saved, "-o", saved), 4)
    assert saved.read_bytes() == before


def test_symlinked_output_is_followed_not_replaced(tmp_path):
    """The pocket's straight edge: any program shows how its output is written."""
    target = tmp_path / "real.json"
    target.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(target)
    cadcnc_cli("path", POCKET, "--faces", "10", "17", *JOB, "-o", link, "--quiet", check=0)
    assert link.is_symlink() and json.loads(target.read_text())["format"] == "cadcnc-program"


def test_a_very_long_output_name_is_a_clear_error(tmp_path):
    run = cadcnc_cli("path", BOSS, "--faces", "4", "5", *JOB, "-o", tmp_path / ("x" * 260
                                                                               + ".json"))
    one_line(run, 4, "file name too long")


@pytest.fixture(scope="module")
def boss_program(boss_cli_outputs) -> str:
    """The program JSON text ``cadcnc path`` writes for the boss's faces 4 5 (computed once
    per session, conftest: the malformed-file tests each edit a copy)."""
    return (boss_cli_outputs[0] / "p.json").read_text()


def _cut(d: dict) -> dict:
    """The first cut segment of a program dict (version 2)."""
    return next(s for s in d["segments"] if s["kind"] == "cut")


@pytest.mark.parametrize("edit, needle", [
    (lambda d: _cut(d).update(faces=[4]), "two values"),
    (lambda d: _cut(d).update(offsets=[3.0]), "two values"),
    (lambda d: _cut(d).update(points=[], contacts=[], normals=[], uv=[], steps=[],
                              commanded=[]), "no points"),
    (lambda d: _cut(d)["points"][3].__setitem__(0, "NaN"), "non-finite"),
    (lambda d: _cut(d)["inputs"].update(radius="NaN"), "radius"),
    (lambda d: d["job"].update(radius="NaN"), "radius"),
    (lambda d: d["segments"][0]["points"][0].__setitem__(2, "NaN"), "non-finite"),
])
def test_malformed_path_json_is_refused_quickly(tmp_path, boss_program, edit, needle):
    """Program JSON (version 2) with a bad cut, job or link is refused with the reason."""
    data = json.loads(boss_program)
    edit(data)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    for command in (["plot", bad, "--part", BOSS, "-o", tmp_path / "x.png"],
                    ["verify", bad, "--part", BOSS]):
        start = time.perf_counter()
        one_line(cadcnc_cli(*command), 2, needle)
        assert time.perf_counter() - start < 10


def test_stream_is_gated_before_the_first_increment(tmp_path):
    program = tmp_path / "slot.apt"
    program.write_text(f"PART = '{SLOT}'\nCUTTER/R=3\nFEED/1500\nPERIOD/4ms\n"
                       "SLOT = P/[F3, F4, EDGE, EDGE]\nFINI\n")
    run = cadcnc_cli("run", program, "--stream")
    assert run.returncode == 5 and run.stdout == "" and "face 5 by 2 mm" in run.stderr


def test_a_path_ending_at_its_stretch_limit_is_complete(tmp_path):
    """The ramp's wall ends 12 mm before the edge does: the stretch ends there (a contact
    reaches its face's boundary), an intended end, so the program is complete (exit 0).
    A program stopped short exits 6: tests/cli/test_cli_program.py."""
    out = tmp_path / "ramp.json"
    args = ["path", FIXTURES / "ramp_wall.step", "--faces", "3", "7", *JOB, "-o", out]
    run = cadcnc_cli(*args)
    assert run.returncode == 0 and out.exists() and "result     complete" in run.stdout
    assert "edge 1, stretch 1: 28.0" in run.stdout
    # nothing on stderr but the gate's progress (shown once it has run 1 s: a loaded machine)
    assert all(line.startswith("cadcnc: path: gouge check: ")
               for line in run.stderr.splitlines()), run.stderr


def test_complete_path_says_so(tmp_path):
    """... and the steps the accuracy shortened are reported like a feed override."""
    run = cadcnc_cli("path", BOSS, "--faces", "4", "5", "--radius", "3", "--feed", "12000",
                     "--period", "4ms", "-o", tmp_path / "b.json")
    assert run.returncode == 0 and "result     complete\n" in run.stdout
    assert "accuracy   feed reduced on " in run.stdout and "for accuracy (0.001 mm)" in run.stdout
    run = cadcnc_cli("path", BOSS, "--faces", "4", "5", *JOB, "-o", "/dev/null/x.json")
    assert run.returncode == 4  # the destination is checked before computing
    ok = cadcnc_cli("verify", FIXTURES / "stretch_shelf.step", "--faces", "11", "8", *JOB,
                    "--quiet")
    assert ok.returncode == 0, ok.stderr


def _cli(*args):
    return [sys.executable, "-m", "cadcnc.cli", *map(str, args)]


@pytest.mark.parametrize("delay", [0.3, 1.2, 2.0])
def test_ctrl_c_at_any_moment_keeps_a_whole_set(tmp_path, delay):
    """Old outputs intact (or the whole new set), no temporary files left, exit 130 (or 0
    when the run had finished). Start-up, computing, writing; the moment after the files
    are in place is the next test's."""
    outs = [tmp_path / f"b{s}" for s in (".json", ".csv", ".ngc")]
    for o in outs:
        o.write_text("old")
    proc = subprocess.Popen(_cli("path", BOSS, "--faces", "4", "5", *JOB,
                                 *[x for o in outs for x in ("-o", o)]),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    contents = [o.read_text() for o in outs]
    assert contents == ["old"] * 3 or all(c != "old" for c in contents), contents
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    assert "Traceback" not in err, err
    assert proc.returncode in (0, 130), proc.returncode
    assert (proc.returncode == 130) == ("cadcnc: interrupted" in err), err


def test_ctrl_c_after_the_files_are_written_keeps_the_exit_code(tmp_path):
    """Was exit -2 (killed by the signal) with the files complete: after ``main`` returned,
    Python's teardown reset SIGINT to the system default and spent ~0.7 s freeing OCCT and
    numba objects. The program now ends at once after flushing its output. The pocket's
    straight edge: the moment after writing is the same for any program."""
    out = tmp_path / "b.json"
    proc = subprocess.Popen(_cli("path", POCKET, "--faces", "10", "17", *JOB, "-o", out),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONUNBUFFERED": "1"})
    for line in proc.stdout:   # the summary's last line: the files are in place
        if line.lstrip().startswith("wrote"):
            proc.send_signal(signal.SIGINT)
            break
    proc.communicate(timeout=60)
    assert proc.returncode in (0, 130), proc.returncode
    assert _cut(json.loads(out.read_text()))["faces"] == [10, 17]


def test_a_255_byte_name_is_written(tmp_path):
    """The longest legal name: the temporary file beside it must fit the limit too."""
    out = tmp_path / ("p" * 250 + ".json")
    assert len(out.name.encode()) == 255
    run = cadcnc_cli("path", POCKET, "--faces", "10", "17", *JOB, "-o", out, "-q")
    assert run.returncode == 0 and out.exists(), run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]


def test_a_dangling_symlink_names_its_target(tmp_path):
    link = tmp_path / "p.json"
    link.symlink_to(tmp_path / "gone" / "p.json")
    run = cadcnc_cli("path", POCKET, "--faces", "10", "17", *JOB, "-o", link)
    assert run.returncode == 4
    assert "symbolic link" in run.stderr and str(tmp_path / "gone") in run.stderr
