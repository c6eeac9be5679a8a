"""`cadcnc finish --strategy waterline|steep-shallow` as a user runs it: the program is
gated whole (moves, links, ramps) and complete, rs274 reads its G-code, the JSON records
the strategy, steep-shallow's one uncut report, bad levels and thresholds refused."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import cadcnc
from cadcnc.core.job import finishing
from cadcnc.io.program_json import read_program
from cadcnc.ops.finish import steep_shallow
from cadcnc.testing.rs274 import move_points
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES
from helpers.marks import needs_rs274
from helpers.programs import commanded

pytestmark = pytest.mark.slow  # over about 5 s a test (pyproject.toml)

BOSS = str(FIXTURES / "wl_boss.step")
FACTS = json.loads((FIXTURES / "waterline_fixtures.json").read_text())


@pytest.fixture(scope="module")
def boss_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("waterline")
    outs = [d / "p.json", d / "p.ngc"]
    run = cadcnc_cli("finish", BOSS, "--faces", "9", "7", "2", "--radius", "2",
                     "--strategy", "waterline", "--stepdown", "2",
                     *[a for o in outs for a in ("-o", o)], check=0)
    return run, outs


def test_the_program_is_gated_complete_and_top_to_bottom(boss_run):
    run, (js, _) = boss_run
    assert run.returncode == 0, run.stderr
    assert "waterline, stepdown 2 mm, climb" in run.stdout and "result     complete" in run.stdout
    assert "verdict    written" in run.stdout
    prog = read_program(js)
    data = json.loads(js.read_text())
    assert (data["job"]["strategy"], data["job"]["stepdown"]) == ("waterline", 2.0)
    assert prog.job.operation.strategy == "waterline"
    z = [c.points[0, 2] for c in prog.cuts]
    assert z == sorted(z, reverse=True) and len(prog.cuts) >= 4
    # every loop closed; the levels moved off the top's offset (17) and the fillet's foot (7)
    assert all(np.linalg.norm(c.points[0] - c.points[-1]) <= 1e-9 for c in prog.cuts)
    assert any("moved to" in n and "horizontal" in n for n in prog.notes)
    # links from one level down to the next stay down where verified clear (a ramp)
    downs = [s for s in prog.links if len(s.points) == 2]
    assert downs, "no stay-down link between levels"


@needs_rs274
def test_rs274_reads_the_waterline_program(boss_run, tmp_path):
    _, (js, ngc) = boss_run
    got = move_points(ngc, tmp_path)
    np.testing.assert_allclose(got[1:], commanded(read_program(js)), atol=1e-3)


@pytest.mark.parametrize("args,words", [
    (["--strategy", "waterline"], "stepdown"),
    (["--strategy", "waterline", "--stepdown", "0"], "stepdown"),
    (["--strategy", "waterline", "--stepdown", "5"], "diameter"),
    (["--strategy", "steep-shallow", "--scallop", "0.1", "--threshold", "95"], "threshold"),
    (["--strategy", "steep-shallow", "--scallop", "0.1", "--overlap", "-1"], "overlap"),
    (["--strategy", "waterline", "--stepdown", "1", "--stepover", "1"], "stepover"),
    # a setting of another strategy is refused by name, not silently dropped
    (["--strategy", "waterline", "--stepdown", "1", "--angle", "30"], "takes no angle"),
    (["--stepover", "1", "--threshold", "50"], "takes no threshold"),
    (["--stepover", "1", "--side", "conventional"], "takes no side"),
])
def test_bad_levels_and_thresholds_write_nothing(tmp_path, args, words):
    out = tmp_path / "p.json"
    run = cadcnc_cli("finish", BOSS, "--faces", "9", "7", "2", "--radius", "2", *args,
                     "-o", out)
    assert run.returncode == 2 and words in run.stderr, run.stderr
    assert not out.exists()


def test_steep_shallow_is_one_program_with_one_uncut_report(monkeypatch):
    """The wall: waterline on the steep part, raster on the shallow, one program and one
    report of the union; the steep part's scallops at or below the limit."""
    part = cadcnc.load_step(FIXTURES / FACTS["wall"]["file"])
    reports = []
    real = steep_shallow.uncut_report
    monkeypatch.setattr(steep_shallow, "uncut_report",
                        lambda *a: reports.append(real(*a)) or reports[-1])
    prog = cadcnc.finish(part, FACTS["wall"]["faces"], radius=3.0, scallop=0.1,
                         strategy="steep-shallow", threshold=45.0, overlap=0.5)
    assert len(reports) == 2   # the steep samples across the levels, the rest the planes
    steep, shallow = reports
    assert steep.limit == 0.1 and 0.0 < steep.max_scallop <= 0.1 + 1e-9
    assert steep.unmachined_area == 0.0
    notes = [n for n in prog.notes if n.startswith("uncut")]
    assert len(notes) == 1
    largest = float(re.search(r"largest scallop ([0-9.e-]+) mm", notes[0]).group(1))
    assert largest == pytest.approx(max(steep.max_scallop, shallow.max_scallop), rel=1e-3)
    flat = [c for c in prog.cuts if np.ptp(c.points[:, 2]) > 1e-6]     # raster passes
    level = [c for c in prog.cuts if np.ptp(c.points[:, 2]) <= 1e-9]  # waterline pieces
    assert flat and level
    slope = np.degrees(np.arccos(np.concatenate([c.path.normals[:, 0, 2] for c in level])))
    assert slope.min() > 45.0 - 15.0   # within the overlap of the steep region
    gate = cadcnc.gate_program(prog, part)
    assert gate.ok


def test_an_old_program_file_with_every_field_still_reads():
    """A program file written before the records split gives every finishing field: the
    ones its strategy has not are left out, not refused."""
    rec = finishing("waterline", (9,), stepdown=1.0, scallop=None, stepover=None, angle=0.0,
                    pattern="zigzag", threshold=45.0, side="climb", overlap=0.0)
    assert rec.strategy == "waterline" and rec.stepdown == 1.0
    with pytest.raises(cadcnc.InputError, match="takes no angle"):
        finishing("waterline", (9,), own_only=True, stepdown=1.0, angle=30.0)
