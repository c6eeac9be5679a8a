"""`cadcnc finish` as a user runs it: outputs agree with each other and with the G-code
rs274 reads, defaults as documented, bad input refused before anything is written."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from cadcnc.io.program_json import read_program
from cadcnc.testing.rs274 import move_points
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES
from helpers.marks import needs_rs274
from helpers.programs import commanded

SLAB = str(FIXTURES / "finish_slab.step")


@pytest.fixture(scope="module")
def slab_run(tmp_path_factory):
    """The slab at stepover 4: every written output is compared point by point, whatever
    the spacing of the planes (8 planes across the 30 mm slab; half the work of 2)."""
    d = tmp_path_factory.mktemp("finish")
    outs = [d / f"p{s}" for s in (".json", ".ngc", ".csv", ".png")]
    run = cadcnc_cli("finish", SLAB, "--faces", "5", "--radius", "3", "--stepover", "4",
                     "--plunge-feed", "300", *[a for o in outs for a in ("-o", o)], check=0)
    return run, outs


def test_outputs_agree(slab_run):
    run, (js, ngc, cs, png) = slab_run
    assert "feed 1500 mm/min, period 4 ms" in run.stdout and "complete" in run.stdout
    assert "largest scallop" in run.stdout and "plane" in run.stderr
    prog = read_program(js)
    data = json.loads(js.read_text())
    assert {s["kind"] for s in data["segments"]} == {"cut", "link"}
    assert data["job"]["operation"] == "finish" and data["job"]["stepover"] == 4.0
    assert prog.job.operation.faces == (5,)
    # ball centres: R' = 3 above the slab's top at every cut point (its top is below z 11.2)
    cut_z = np.concatenate([np.array(s["points"])[:, 2] for s in data["segments"]
                            if s["kind"] == "cut"])
    assert cut_z.min() > 3.0 - 2.0 and len(prog.cuts) >= 8   # 30 mm / 4
    rows = list(csv.DictReader(cs.open()))
    pts = np.array([[float(r[k]) for k in ("x", "y", "z")] for r in rows])
    np.testing.assert_allclose(pts, np.vstack([c.points for c in prog.cuts]), atol=1e-6)
    assert "F300" in ngc.read_text()
    assert png.read_bytes()[:4] == b"\x89PNG"


@needs_rs274
def test_rs274_reads_the_finish_program(slab_run, tmp_path):
    _, (js, ngc, _, _) = slab_run
    got = move_points(ngc, tmp_path)
    np.testing.assert_allclose(got[1:], commanded(read_program(js)), atol=1e-3)


@pytest.mark.parametrize("args,code,words", [
    (["--faces", "99", "--stepover", "1"], 2, "99"),
    (["--faces", "5", "--stepover", "1", "--scallop", "0.01"], 2, "not allowed with"),
    (["--faces", "5"], 2, "--stepover"),
    (["--faces", "5", "--stepover", "-1"], 2, "stepover"),
    (["--faces", "5", "--stepover", "1", "--angle", "east"], 2, "--angle"),
    (["--faces", "6", "--stepover", "1"], 2, "points down"),
])
def test_bad_input_writes_nothing(tmp_path, args, code, words):
    out = tmp_path / "p.json"
    run = cadcnc_cli("finish", SLAB, "--radius", "3", *args, "-o", out)
    assert run.returncode == code and words in run.stderr, run.stderr
    assert not out.exists()
