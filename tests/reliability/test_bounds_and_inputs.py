"""No setting turns the gate off, and every input error is named (issue 20).

- Every bounded tolerance of docs/reliability.md's table is enforced at its bound, in the
  library and on the command line.
- Program JSON with a huge integer, deep nesting, a NaN point or the wrong version, and
  wrong argument types in the API, give an InputError naming the problem: no traceback.
"""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import pytest

import cadcnc
from cadcnc.core.errors import InputError
from cadcnc.core.job import Job, PairPath, Pencil, Raster, Tool
from cadcnc.core.tolerances import BOUNDS, CHORD_TOLERANCE_MAX, DEFAULT
from cadcnc.io.program_cq import to_cq
from cadcnc.verification import gouge_gate, verify
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES
from helpers.programs import pencil_run

POCKET = FIXTURES / "pocket.step"   # faces 10 17: a straight edge, a program in ~0.2 s
PATH = ["path", POCKET, "--faces", "10", "17", "--radius", "3"]
DOCS = Path(__file__).resolve().parents[2] / "docs" / "reliability.md"


def test_the_docs_table_is_the_librarys():
    """docs/reliability.md's bounds table has one row per bounded tolerance, same values."""
    rows = re.findall(r"^\| `(\w+)` \| ([^|]+) \| ([^|]+) \|", DOCS.read_text(), re.M)
    table = {name: (float(lo), float(hi)) for name, lo, hi in rows if name in BOUNDS}
    assert table == BOUNDS


@pytest.mark.parametrize("name", sorted(BOUNDS))
def test_each_bound_is_enforced(name):
    lo, hi = BOUNDS[name]
    loose, at = (hi * 1.01, hi) if name != "coverage" else (lo * 0.99, lo)
    dataclasses.replace(DEFAULT, **{name: at})            # the bound itself is allowed
    with pytest.raises(InputError, match=name):
        dataclasses.replace(DEFAULT, **{name: loose})      # one step looser is not


@pytest.mark.parametrize("flag, value, needle", [
    ("--gouge-tolerance", "1e6", "over its bound 0.1 mm"),
    ("--gouge-tolerance", "0.11", "over its bound 0.1 mm"),
    ("--tolerance", f"{CHORD_TOLERANCE_MAX * 2:g}", "over its bound"),
])
def test_the_command_line_refuses_a_looser_setting(flag, value, needle, tmp_path):
    out = tmp_path / "p.ngc"
    run = cadcnc_cli(*PATH, flag, value, "-o", out)
    assert run.returncode == 2 and needle in run.stderr and not out.exists()


def test_at_the_bounds_the_program_is_still_judged(tmp_path):
    """The loosest limits allowed (gouge 0.1 mm, chord 0.1 mm) and the lowest clearance
    allowed still give a program that the gate judged: its written moves keep the ball
    within the gouge limit of every face, by the gate (0) or refused (5), never switched
    off: the G-code's G64 P is a tenth of the limit, not the limit itself."""
    out = tmp_path / "p.ngc"
    top = cadcnc.load_step(POCKET).top
    run = cadcnc_cli(*PATH, "--gouge-tolerance", "0.1", "--tolerance", "0.1",
                     "--clearance", f"{top + 3:g}", "-o", out, "-q", check=0)
    assert run.returncode in (0, 5)
    if run.returncode == 0:
        assert "G64 P0.01" in out.read_text()


# -- program JSON --------------------------------------------------------------------------
@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    out = tmp_path_factory.mktemp("saved") / "p.json"
    cadcnc_cli(*PATH, "-o", out, "-q", check=0)
    return json.loads(out.read_text())


def _cut(d):
    return next(s for s in d["segments"] if s["kind"] == "cut")


@pytest.mark.parametrize("case, needle", [
    ("bigint", "4300 digits"),
    ("deep", "recursion"),
    ("nan", "non-finite"),
    ("version", "version 99 is not supported"),
    ("segments", "malformed"),
    ("job", "job must be an object"),
])
def test_a_bad_program_json_is_named(saved, case, needle, tmp_path):
    text = {
        "bigint": '{"format": "cadcnc-program", "version": ' + "9" * 5000 + "}",
        "deep": "[" * 100_000 + "]" * 100_000,
        "nan": json.dumps({**saved, "segments": [
            s if s["kind"] == "cut" else {**s, "points": [[float("nan")] * 3] * 2}
            for s in saved["segments"]]}),
        "version": json.dumps({**saved, "version": 99}),
        "segments": json.dumps({**saved, "segments": 5}),
        "job": json.dumps({**saved, "job": "x"}),
    }[case]
    bad = tmp_path / "bad.json"
    bad.write_text(text)
    for command in (["verify", bad], ["plot", bad, "-o", tmp_path / "p.png"]):
        run = cadcnc_cli(*command)
        assert run.returncode == 2, run.stderr
        assert "Traceback" not in run.stderr and needle in run.stderr, run.stderr


# -- the API's argument types --------------------------------------------------------------
@pytest.fixture(scope="module")
def block():
    return cadcnc.load_step(FIXTURES / "step_block.step")


API_CASES = {
    "pencil radius": (lambda p: pencil_run(p, radius="3"), "radius"),
    "pencil faces": (lambda p: pencil_run(p, radius=3.0, faces=5), "faces"),
    "pencil side": (lambda p: pencil_run(p, radius=3.0, side=1), "side"),
    "finish faces": (lambda p: cadcnc.finish(p, "x", radius=3.0, stepover=1.0), "faces"),
    "finish stepover": (lambda p: cadcnc.finish(p, [5], radius=3.0, stepover="1"),
                        "stepover"),
    "run job": (lambda p: cadcnc.run(p, "pencil"), "job"),
    "Job tool": (lambda p: Job(3, 1500.0, 0.004), "tool"),
    "Job operation": (lambda p: Job(Tool(3.0), 1500.0, 0.004, "pencil"), "operation"),
    "PairPath faces": (lambda p: PairPath(faces=5), "two faces"),
    "Pencil faces": (lambda p: Pencil(faces=[0]), "face numbers"),
    "Finish faces": (lambda p: Raster(None, stepover=1.0), "faces"),
    "load_step": (lambda p: cadcnc.load_step(123), "path"),
    "verify": (lambda p: verify(None, p), "toolpath"),
    "gouge_gate": (lambda p: gouge_gate("x", p), "toolpath"),
    "gate_program": (lambda p: cadcnc.gate_program("x", p), "program"),
    "to_cq": (lambda p: to_cq("x"), "program"),
    "read_program": (lambda p: cadcnc.read_program(5), "file"),
}


@pytest.mark.parametrize("case", sorted(API_CASES))
def test_a_wrong_argument_type_is_named(block, case):
    call, needle = API_CASES[case]
    with pytest.raises(InputError, match=needle):
        call(block)


def test_a_run_message_prints_plain_numbers(tmp_path):
    """Was: "at the start tangency (np.float64(42.9968), ...)" in a `run` error."""
    apt = tmp_path / "big.apt"
    apt.write_text(f"PARTNO/'t'\nPART = '{FIXTURES / 'bspline_boss.step'}'\nCUTTER/R=30\n"
                   "FEED/1500\nPERIOD/4ms\nBOSS = P/[F4, F5, EDGE, EDGE]\nFINI\n")
    run = cadcnc_cli("run", apt)
    assert run.returncode == 3 and "np.float64" not in run.stderr + run.stdout
    assert re.search(r"tangency \(-?\d+\.\d{4}, -?\d+\.\d{4}, -?\d+\.\d{4}\)", run.stderr)


def test_pencil_refuses_a_clearance_below_the_top(tmp_path):
    """Was: `pencil step_block --clearance -1000` started with G0 Z13 under the top (20)
    and rapid sideways there. Now refused before computing, naming the lowest value."""
    out = tmp_path / "p.ngc"
    run = cadcnc_cli("pencil", FIXTURES / "step_block.step", "--radius", "3",
                     "--clearance", "-1000", "-o", out)
    assert run.returncode == 2 and "lowest allowed is 23 mm" in run.stderr
    assert not out.exists()


def test_a_refused_program_says_so_after_its_summary(tmp_path):
    """Was: a refused finish printed "status complete", then "refused". The summary's
    last line is the verdict: nothing written, with the exit code (a 0.016 mm ball over
    the ridge's convex edge, which the gate refuses: docs/reliability.md)."""
    out = tmp_path / "p.json"
    run = cadcnc_cli("finish", FIXTURES / "finish_ridge.step", "--faces", "3", "4",
                     "--radius", "0.0160072", "--stepover", "10.9", "-o", out, "-o",
                     tmp_path / "p.ngc")
    assert run.returncode == 5 and not out.exists()
    summary = run.stdout.splitlines()
    verdict = next(k for k, line in enumerate(summary) if line.startswith("  verdict"))
    assert summary[verdict - 1] == "  result     complete"
    assert summary[verdict] == "  verdict    nothing written (exit 5: see the message above)"
