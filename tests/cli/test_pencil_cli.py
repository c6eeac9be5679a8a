"""`cadcnc pencil` as a user runs it: outputs agree with each other and with the API,
defaults as documented, bad input refused before anything is written."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from cadcnc.cli import operation_options as operation_cli
from cadcnc.core import job as job_module
from cadcnc.core.units import parse_duration, parse_feed
from cadcnc.io.gcode import programmed_moves
from cadcnc.io.program_json import read_program
from cadcnc.testing.rs274 import move_points
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES
from helpers.marks import needs_rs274
from helpers.programs import commanded

BLOCK = str(FIXTURES / "step_block.step")


@pytest.fixture(scope="module")
def block_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("pencil")
    outs = [d / f"p{s}" for s in (".json", ".ngc", ".csv", ".png")]
    run = cadcnc_cli("pencil", BLOCK, "--radius", "3", "--plunge-feed", "300",
                     *[a for o in outs for a in ("-o", o)], check=0)
    return run, outs


def test_defaults_are_the_operations():
    assert parse_feed(operation_cli.DEFAULT_FEED) == job_module.DEFAULT_FEED
    assert parse_duration(operation_cli.DEFAULT_PERIOD) == job_module.DEFAULT_PERIOD


def test_outputs_agree(block_run):
    run, (js, ngc, cs, png) = block_run
    assert "feed 1500 mm/min, period 4 ms" in run.stdout and "complete" in run.stdout
    prog = read_program(js)
    data = json.loads(js.read_text())
    assert {s["kind"] for s in data["segments"]} == {"cut", "link"}
    assert len(prog.cuts) == 1 and prog.cut_length > 50  # the step's one 60 mm corner
    rows = list(csv.DictReader(cs.open()))
    pts = np.array([[float(r[k]) for k in ("x", "y", "z")] for r in rows])
    np.testing.assert_allclose(pts, np.vstack([c.points for c in prog.cuts]), atol=1e-6)
    moves, want = programmed_moves(ngc.read_text()), commanded(prog)
    np.testing.assert_allclose(moves[-len(want):], want, atol=1e-3)
    assert "F300" in ngc.read_text()
    assert png.read_bytes()[:4] == b"\x89PNG"


@needs_rs274
def test_rs274_reads_the_pencil_program(block_run, tmp_path):
    _, (js, ngc, _, _) = block_run
    got = move_points(ngc, tmp_path)
    want = commanded(read_program(js))
    np.testing.assert_allclose(got[1:], want, atol=1e-3)  # got[0]: the machine's home


def test_bad_input_writes_nothing(tmp_path):
    out = tmp_path / "p.json"
    run = cadcnc_cli("pencil", BLOCK, "--radius", "3", "-o", out, "-o", tmp_path / "p.txt")
    assert run.returncode == 4 and "unknown output format" in run.stderr
    run = cadcnc_cli("pencil", BLOCK, "--radius", "3", "--faces", "99", "-o", out)
    assert run.returncode == 2 and "99" in run.stderr
    run = cadcnc_cli("pencil", BLOCK, "--radius", "3", "--faces", "1", "2", "-o", out)
    assert run.returncode == 3 and "no cut left" in run.stderr   # valid input, no program
    assert not out.exists()
