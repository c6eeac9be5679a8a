"""``cadcnc path`` writes programs: every stretch of a corner cut, linked, gated as a whole.

Fixtures (fixtures/stretch_fixtures.json holds their closed-form stretches): the shelf's
corner has two stretches (the shank hits a shelf in between), the boss on a curved floor
two mirror stretches. Outputs are parsed back and compared with the library's program;
G-code goes through LinuxCNC's rs274.
"""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest

import cadcnc
from cadcnc.core.job import Job, PairPath, Tool
from cadcnc.io.outputs import PROGRAM_CSV_COLUMNS
from cadcnc.io.program_gcode import segment_moves
from cadcnc.io.program_json import read_program
from cadcnc.io.toolpath_csv import CSV_COLUMNS
from cadcnc.ops import common
from cadcnc.ops.path import pair_program
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "stretch_fixtures.json").read_text())
SHELF = FIXTURES / FACTS["shelf"]["file"]
BOSS = FIXTURES / FACTS["boss"]["file"]
JOB = ["--radius", "3", "--feed", "1500", "--period", "4ms"]
SHELF_JOB = ["--faces", "11", "8", *JOB]
BOSS_JOB = ["--faces", "1", "6", *JOB]


@pytest.fixture(scope="module")
def shelf(tmp_path_factory):
    """The shelf's program written as JSON, CSV and G-code (plunge at 300 mm/min)."""
    d = tmp_path_factory.mktemp("shelf")
    run = cadcnc_cli("path", SHELF, *SHELF_JOB, "--plunge-feed", "300", "-o", d / "s.json",
                     "-o", d / "s.csv", "-o", d / "s.ngc", check=0)
    return d, run, read_program(d / "s.json")


@pytest.fixture(scope="module")
def shelf_api():
    part = cadcnc.load_step(SHELF)
    job = Job(Tool(3.0), 1500.0, 0.004, PairPath(faces=(11, 8), edge=None), source=str(SHELF))
    return pair_program.program_for_job(part, job)


def test_two_stretches_give_two_cuts_and_a_link(shelf, shelf_api):
    d, run, prog = shelf
    assert [s.kind for s in prog.segments] == ["link", "cut", "link", "cut", "link"]
    assert [(c.edge, c.stretch) for c in prog.cuts] == [(1, 1), (1, 2)]
    for got, want in zip(prog.segments, shelf_api.segments):
        np.testing.assert_array_equal(got.points, want.points)
    assert prog.complete and json.loads((d / "s.json").read_text())["version"] == 2
    # the summary lists every cut with its edge, stretch, length and stop; then the verdict
    for k, cut in enumerate(shelf_api.cuts, 1):
        assert (f"cut {k}: faces 11 8, edge 1, stretch {k}: {cut.length:.4f} mm, "
                f"{len(cut.points)} points") in run.stdout
    assert "links      3 (" in run.stdout and "result     complete" in run.stdout
    assert "np.float64" not in run.stdout + run.stderr


def test_csv_has_a_segment_column(shelf, shelf_api):
    d, _, _ = shelf
    lines = (d / "s.csv").read_text().splitlines()
    assert lines[0].split(",") == PROGRAM_CSV_COLUMNS == ["segment", *CSV_COLUMNS]
    rows = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    # rows of the cuts only, numbered by their place among the segments (2 and 4)
    assert sorted(set(rows[:, 0].astype(int))) == [2, 4]
    for seg in (2, 4):
        np.testing.assert_array_equal(rows[rows[:, 0] == seg][:, 3:6],
                                      shelf_api.segments[seg - 1].points)


def test_gcode_segments_are_the_program_moves(shelf, shelf_api):
    """Each segment's written moves are its points (rounded to the 4 decimals written)."""
    d, _, _ = shelf
    text = (d / "s.ngc").read_text()
    assert re.findall(r"\(segment (\d+): (cut|link)", text) == [
        ("1", "link"), ("2", "cut"), ("3", "link"), ("4", "cut"), ("5", "link")]
    moves = segment_moves(text)
    assert len(moves) == 5
    for got, seg in zip(moves, shelf_api.segments):
        np.testing.assert_allclose(got[-len(seg.points):] if seg.kind == "link" else got,
                                   seg.points, rtol=0, atol=0.5e-4 + 1e-9)
    assert "F300" in text and "F1500" in text


@pytest.mark.skipif(shutil.which("rs274") is None, reason="LinuxCNC rs274 not installed")
def test_rs274_reads_the_program(shelf, shelf_api, tmp_path):
    """rs274's feed moves are the cuts' points and the links' plunges, its traverses the
    links' rapids, in order, with the plunge feed then the cutting feed."""
    from cadcnc.io.gcode_reader import canonical_calls
    from cadcnc.testing.rs274 import feed_points

    d, _, _ = shelf
    text = (d / "s.ngc").read_text()
    feeds = feed_points(tmp_path, text)
    calls = canonical_calls(tmp_path / "prog.ngc", strict=True)
    traverses = np.array([[float(v) for v in args[:3]] for name, args in calls
                          if name == "STRAIGHT_TRAVERSE"])
    want_feed, want_rapid = [], []
    for seg in shelf_api.segments:
        if seg.kind == "cut":
            want_feed += list(seg.points[1:])  # the first point is where the plunge ended
            continue
        for p, rapid in zip(seg.points[1:], seg.rapid):
            (want_rapid if rapid else want_feed).append(p)
    half = 0.5e-4 + 1e-9
    np.testing.assert_allclose(feeds, np.array(want_feed), rtol=0, atol=half)
    # rs274 adds the header's two rapids (to the first height, then over the start)
    np.testing.assert_allclose(traverses[2:], np.array(want_rapid), rtol=0, atol=half)
    rates = [float(args[0]) for name, args in calls if name == "SET_FEED_RATE"]
    assert [r for r in rates if r] == [300.0, 1500.0, 300.0, 1500.0]


def test_edge_and_stretch_select(tmp_path):
    out = tmp_path / "two.json"
    run = cadcnc_cli("path", SHELF, *SHELF_JOB, "--edge", "1", "--stretch", "2", "-o", out,
                     check=0)
    prog = read_program(out)
    assert [(c.edge, c.stretch) for c in prog.cuts] == [(1, 2)]
    np.testing.assert_allclose(prog.cuts[0].points[-1], FACTS["shelf"]["stretches"][1]["end"]["p"],
                               atol=pair_program.LIMIT_SLACK)
    assert "cut 1: faces 11 8, edge 1, stretch 2" in run.stdout
    for extra, needle in ((["--stretch", "3"], "there is no stretch 3"),
                          (["--edge", "2"], "there is no edge 2"),
                          (["--stretch", "0"], "--stretch numbers the stretches")):
        run = cadcnc_cli("path", SHELF, *SHELF_JOB, *extra, "-o", tmp_path / "x.json")
        assert run.returncode == 2 and needle in run.stderr, run.stderr
        assert not (tmp_path / "x.json").exists()


def test_a_clearance_below_the_top_is_refused_with_the_lowest_allowed(tmp_path):
    """The links' height must keep the ball above the part's top: a lower --clearance is
    refused before anything is computed (exit 2, nothing written), naming the lowest
    allowed height; with --tool-tip the same limit counts for the tip."""
    out = tmp_path / "b.json"
    args = ["path", BOSS, *BOSS_JOB, "-o", out]
    top = cadcnc.load_step(BOSS).top
    run = cadcnc_cli(*args, "--clearance", "0")
    assert run.returncode == 2 and not out.exists()
    assert f"lowest allowed is {top + 3:g} mm" in run.stderr
    run = cadcnc_cli(*args, "--clearance", f"{top + 2.9:g}", "--tool-tip", "-q")
    assert run.returncode == 0 and out.exists()
    assert read_program(out).links[0].points[:, 2].max() == pytest.approx(top + 5.9)


def test_the_gate_catches_a_gouging_link():
    """A link forced through the boss (its rapid lowered to Z 2.8, under the boss top) is
    refused by the library's verdict with the link named, and allowed only on request."""
    from cadcnc.pipeline.exit_policy import judge
    from cadcnc.program.program import LinkSegment, Program

    part = cadcnc.load_step(BOSS)
    job = Job(Tool(3.0), 1500.0, 0.004, PairPath(faces=(1, 6), edge=None))
    program = pair_program.program_for_job(part, job)
    assert judge(program, part, "path").code == 0
    segs = list(program.segments)
    k = next(i for i, seg in enumerate(segs) if seg.kind == "link" and 0 < i < len(segs) - 1)
    low = segs[k].points.copy()
    low[1:-1, 2] = 2.8
    segs[k] = LinkSegment(low, segs[k].rapid)
    verdict = judge(Program(job, segs), part, "path")
    assert verdict.code == 5 and not verdict.write
    assert "cut 2 (faces 1 6, edge 1, stretch 2) or the link moves to it" in verdict.messages[0]
    assert "--clearance" not in verdict.messages[0]   # no hint at an option that cannot help
    allowed = judge(Program(job, segs), part, "path", allow_gouge=True)
    assert allowed.code == 5 and allowed.write and "written anyway" in allowed.messages[0]


def test_a_program_stopped_short_exits_6(tmp_path, monkeypatch):
    """A cut stopped by the cycle limit (a real stop of the stepper, forced low here) leaves
    the rest of its stretch listed as stopped short: exit 6, nothing written unless
    --allow-partial (still 6); the summary says partial and why."""
    real = common.stepper_for
    monkeypatch.setattr(common, "stepper_for", lambda plan, max_cycles, record, **kw: real(
        plan, 40, record, check_cycles=False, **kw))  # a deliberately short run, as documented
    out = tmp_path / "p.json"
    args = ["path", SHELF, *SHELF_JOB, "--stretch", "1", "-o", out]
    run = cadcnc_cli(*args)
    assert run.returncode == 6 and not out.exists()
    assert "partial: cut 1:" in run.stderr and "--allow-partial writes it" in run.stderr
    run = cadcnc_cli(*args, "--allow-partial")
    assert run.returncode == 6 and out.exists()
    prog = read_program(out)
    assert not prog.complete and prog.skipped[0].reason == "stopped short"
    assert "result     partial: cut 1:" in run.stdout
    assert "skipped    faces 11 8 edge 1: stopped short: stretch 1 of edge 1" in run.stdout


def test_verify_and_plot_read_a_program(shelf, tmp_path):
    d, _, _ = shelf
    run = cadcnc_cli("verify", d / "s.json", "--json", check=0)
    data = json.loads(run.stdout)
    assert data["ok"] and [c["cut"] for c in data["cuts"]] == [
        "cut 1 (faces 11 8, edge 1, stretch 1)", "cut 2 (faces 11 8, edge 1, stretch 2)"]
    assert all(c["max_overcut_mm"] < 1e-3 for c in data["cuts"])
    strict = cadcnc_cli("verify", d / "s.json", "--gouge-tolerance", "1e-12", "-q")
    assert strict.returncode in (0, 5)
    out = tmp_path / "s.png"
    run = cadcnc_cli("plot", d / "s.json", "-o", out, check=0)
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_verify_judges_the_links_too(tmp_path):
    """`verify` of a saved program whose link runs through the boss exits 5 and says the
    links fail, although every cut passes its own report."""
    from cadcnc.io.program_json import program_json
    from cadcnc.program.program import LinkSegment, Program

    part = cadcnc.load_step(BOSS)
    job = Job(Tool(3.0), 1500.0, 0.004, PairPath(faces=(1, 6), edge=None), source=str(BOSS))
    program = pair_program.program_for_job(part, job)
    segs = list(program.segments)
    k = next(i for i, seg in enumerate(segs) if seg.kind == "link" and 0 < i < len(segs) - 1)
    low = segs[k].points.copy()
    low[1:-1, 2] = 2.8
    segs[k] = LinkSegment(low, segs[k].rapid)
    bad, good = tmp_path / "bad.json", tmp_path / "good.json"
    bad.write_text(program_json(Program(job, segs)))
    good.write_text(program_json(program))
    run = cadcnc_cli("verify", bad, "-q")
    assert run.returncode == 5 and "links fail the gouge gate" in run.stderr
    assert cadcnc_cli("verify", good, "-q").returncode == 0


def test_verify_refuses_a_program_over_its_point_limit(tmp_path, monkeypatch):
    """Work is bounded before it starts: over the limit, verify names the estimate."""
    from cadcnc.pipeline import saved

    out = tmp_path / "s.json"
    cadcnc_cli("path", SHELF, *SHELF_JOB, "-o", out, "-q", check=0)
    monkeypatch.setattr(saved, "MAX_VERIFY_POINTS", 100)
    run = cadcnc_cli("verify", out)
    assert run.returncode == 2 and "points, over the limit of 100" in run.stderr
