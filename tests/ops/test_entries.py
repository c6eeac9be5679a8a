"""Entries through free space (cadcnc/ops/entries.py, docs/program.md "Entries"), on the entry
fixtures (fixtures/build_entry_fixtures.py): a corner under overhangs higher than the
shank is entered at its clear end, at a clear point between (cut both ways), or from the
side; a corner in a sealed void is skipped as `unreachable`; finishing passes under an
overhang are entered the same way. Every link move is checked by OCCT independently of
cadcnc (benchmarks/entries/sweeps.py: the ball and a 10 R shank swept along the move), and
nothing is refused as a gouge because of a link."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import EXIT_GOUGE, EXIT_NOTHING, EXIT_OK
from cadcnc.core.job import Job, PairPath, Tool
from cadcnc.ops.common import safe_height
from cadcnc.pipeline.exit_policy import judge
from cadcnc.program.linking import linked
from cadcnc.program.program import Program
from cadcnc.program.toolpath import toolpath_piece
from cadcnc.testing.coverage_oracle import Oracle, read_shape
from cadcnc.testing.tool_sweeps import TOL, entries_at, entry_exists, links_check
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES, fixture_path

pytestmark = [pytest.mark.slow, pytest.mark.cli]

FACTS = json.loads((FIXTURES / "entry_fixtures.json").read_text())
R = 2.0
SHANK = 10 * R
FAST = ["--radius", f"{R:g}", "--period", "20ms"]   # a 0.5 mm step: fewer points to gate
Z_SAFE = 50.0    # the parts' top (40) + 10: the default link height
OVERHANG_Y = {"entry_end": [(0, 15)], "entry_middle": [(0, 12), (28, 40)],
              "entry_side": [(0, 40)]}   # as built, x 25..40, z 36..40


def _run(tmp_path_factory, name: str, *args) -> tuple:
    out = tmp_path_factory.mktemp(name) / "p.json"
    run = cadcnc_cli(*args, "-o", out)
    return run, (json.loads(out.read_text()) if out.exists() else None)


def _path(tmp_path_factory, name: str) -> tuple:
    f = FACTS[name]
    return _run(tmp_path_factory, name, "path", FIXTURES / f["file"], "--faces",
                f["floor"], f["wall"], *FAST)


@pytest.fixture(scope="module")
def oracles():
    return {name: Oracle(read_shape(str(FIXTURES / f["file"]))) for name, f in FACTS.items()}


@pytest.fixture(scope="module")
def paths(tmp_path_factory):
    return {name: _path(tmp_path_factory, name) for name in FACTS}


def _cut_points(program) -> np.ndarray:
    return np.vstack([s["points"] for s in program["segments"] if s["kind"] == "cut"])


def _under_overhang(p, name) -> bool:
    """Whether a plunge onto ball centre p crosses an overhang (closed form: the shank's
    circle of radius R' around p meets x 25..40 over the overhang's y range)."""
    return any(25.0 - R < p[0] and y0 - R < p[1] < y1 + R for y0, y1 in OVERHANG_Y[name])


@pytest.mark.parametrize("name", ["entry_end", "entry_middle", "entry_side"])
def test_corner_under_overhangs_is_cut_whole_and_linked_clear(paths, oracles, name):
    """Exit 0 (a complete, gated program); the cuts cover the whole corner y 0..40 on
    x 38, z 12 (closed form); every link move keeps the ball and the 10 R shank at least
    R' - 1 µm from every face by OCCT; nothing refused."""
    run, program = paths[name]
    assert run.returncode == EXIT_OK, run.stderr
    assert "refused" not in run.stderr
    pts = _cut_points(program)
    assert np.allclose(pts[:, [0, 2]], [38.0, 12.0], atol=1e-6)
    ys = np.sort(pts[:, 1])
    assert ys[0] < 1e-6 and ys[-1] > 40.0 - 1e-6 and np.diff(ys).max() <= 0.5 + 1e-6
    check = links_check(oracles[name], program, R, SHANK)
    assert check["bad"] == 0 and check["worst_mm"] <= TOL, check
    assert any(n.startswith("entries: ") for n in program["notes"])


def test_end_entry_plunges_beside_the_overhang(paths):
    """entry_end: the plunge lands where no overhang is over the corner (its start lies
    under one), the cut runs from there, and the tool leaves where it came in."""
    _, program = paths["entry_end"]
    segs = program["segments"]
    first_cut = next(s for s in segs if s["kind"] == "cut")
    start = np.asarray(first_cut["points"][0])
    assert not _under_overhang(start, "entry_end")
    down = np.asarray(segs[0]["points"])
    assert np.allclose(down[:, :2], start[:2]) and down[0, 2] >= Z_SAFE - 1e-9
    up = np.asarray(segs[-1]["points"])
    assert np.allclose(up[-1, :2], start[:2]) and up[-1, 2] >= Z_SAFE - 1e-9


def test_middle_entry_cuts_both_ways(paths):
    """entry_middle: both ends lie under overhangs; two cuts start at one clear point
    between (the first of the sampled points clear of the overhang at y 12), one to
    each end; every plunge and retract is outside the overhangs."""
    _, program = paths["entry_middle"]
    cuts = [np.asarray(s["points"]) for s in program["segments"] if s["kind"] == "cut"]
    assert len(cuts) == 2 and np.allclose(cuts[0][0], cuts[1][0])
    assert not _under_overhang(cuts[0][0], "entry_middle")
    assert {round(c[-1][1]) for c in cuts} == {0, 40}
    for s in program["segments"]:
        if s["kind"] == "link":
            pts, rapid = np.asarray(s["points"]), s["rapid"]
            for k, fast in enumerate(rapid):
                vertical = np.allclose(pts[k, :2], pts[k + 1, :2])
                if vertical and max(pts[k, 2], pts[k + 1, 2]) > 30.0:
                    assert not _under_overhang(pts[k], "entry_middle")


def test_side_entry_comes_in_at_the_corner_height(paths, oracles):
    """entry_side: no plunge reaches the corner (closed form: the overhang covers it all);
    the approach descends outside the part's box and comes in horizontally at z 12."""
    _, program = paths["entry_side"]
    approach = np.asarray(program["segments"][0]["points"])
    assert approach[-1][2] == pytest.approx(12.0)
    outside = approach[-2]
    assert outside[2] == pytest.approx(12.0) and (outside[0] < -R or outside[1] < -R
                                                  or outside[1] > 40 + R)
    assert not entry_exists({"plunge": entries_at(oracles["entry_side"], approach[-1], R,
                                                  SHANK, Z_SAFE)["plunge"]}, R)


def test_sealed_void_corner_is_skipped_unreachable(paths, oracles):
    """entry_sealed: exit 3 (nothing reachable from valid input), the reason names
    `unreachable`, the point and the face in the way; OCCT confirms at that point that
    no plunge nor side approach is clear, and that the named face blocks the plunge."""
    run, program = paths["entry_sealed"]
    assert run.returncode == EXIT_NOTHING and program is None
    m = re.search(r"unreachable: .*?\(([-\d.]+), ([-\d.]+), ([-\d.]+)\): shank touches face "
                  r"(\d+)", run.stderr)
    assert m, run.stderr
    p, face = np.array([float(x) for x in m.groups()[:3]]), int(m.group(4))
    ways = entries_at(oracles["entry_sealed"], p, R, SHANK, Z_SAFE)
    assert not entry_exists(ways, R), ways
    d, blocking = ways["plunge"]
    assert d < R - TOL and blocking == face


def test_finish_passes_under_an_overhang(tmp_path_factory, oracles):
    """Finishing the floor of entry_side one way: passes end under the overhang (at the
    wall), where the retract would cross it. Each pass is left back along itself; the
    program is complete and gated (exit 0), every link clear by OCCT."""
    f = FACTS["entry_side"]
    run, program = _run(tmp_path_factory, "finish", "finish", FIXTURES / f["file"],
                        "--faces", f["floor"], "--stepover", "8", "--pattern", "oneway",
                        *FAST)
    assert run.returncode == EXIT_OK, run.stderr
    assert "refused" not in run.stderr
    ends = [np.asarray(s["points"][-1]) for s in program["segments"] if s["kind"] == "cut"]
    assert ends and all(_under_overhang(e, "entry_side") for e in ends)
    check = links_check(oracles["entry_side"], program, R, SHANK)
    assert check["bad"] == 0 and check["worst_mm"] <= TOL, check


def test_pencil_enters_between_the_overhangs(tmp_path_factory, oracles):
    """Pencil on entry_middle cuts the floor / wall corner (before: skipped as not
    reachable from +Z) with the same rule; exit 0, links clear by OCCT."""
    run, program = _run(tmp_path_factory, "pencil", "pencil",
                        FIXTURES / FACTS["entry_middle"]["file"], *FAST)
    assert run.returncode == EXIT_OK, run.stderr
    pts = _cut_points(program)
    corner = pts[np.isclose(pts[:, 0], 38.0) & np.isclose(pts[:, 2], 12.0)]
    assert corner[:, 1].min() < 1e-6 and corner[:, 1].max() > 40 - 1e-6
    check = links_check(oracles["entry_middle"], program, R, SHANK)
    assert check["bad"] == 0 and check["worst_mm"] <= TOL, check


def test_a_reversed_piece_is_the_same_chords_backwards():
    """toolpath_piece: a reversed piece holds the points backwards, each step the same
    chord's length, each step's bound (eq. 16) the forward bound of that same chord and
    each point's curvature its own; a forward piece is a plain slice."""
    tp = fixture_path("bspline_boss", 4, 5, period=0.02)
    lo, hi = 3, len(tp) - 4
    back = toolpath_piece(tp, lo, hi, reverse=True)
    assert np.array_equal(back.points, tp.points[lo:hi + 1][::-1])
    chords = np.linalg.norm(np.diff(back.points, axis=0), axis=1)
    np.testing.assert_allclose(back.steps[1:], chords, rtol=1e-12, atol=1e-12)
    assert back.length == pytest.approx(float(tp.steps[lo + 1:hi + 1].sum()), rel=1e-12)
    for b, f in zip(back.bounds, tp.bounds):
        assert np.array_equal(b.eq16[:-1], f.eq16[lo:hi][::-1])
        assert np.array_equal(b.k, f.k[lo:hi + 1][::-1])
    ahead = toolpath_piece(tp, lo, hi)
    assert np.array_equal(ahead.points, tp.points[lo:hi + 1])
    assert np.array_equal(ahead.steps[1:], tp.steps[lo + 1:hi + 1])


def test_a_blocked_plunge_is_refused_without_a_useless_hint():
    """The same cut of entry_side linked the old way (a plunge through the overhang) is
    refused by the gate (exit 5, which entries avoid), and the message suggests no option
    that cannot help: no --clearance, --radius or --tolerance, only --allow-gouge."""
    f = FACTS["entry_side"]
    part = cadcnc.load_step(FIXTURES / f["file"])
    job = Job(Tool(R), 1500.0, 0.02, PairPath(faces=(f["floor"], f["wall"])))
    entered = cadcnc.run(part, job)
    old = Program(job, linked(entered.cuts, safe_height(part, job)))
    verdict = judge(old, part, "path")
    assert verdict.code == EXIT_GOUGE and any(verdict.gate.link_failed)
    text = " ".join(verdict.messages)
    assert "--allow-gouge" in text
    assert not any(opt in text for opt in ("--clearance", "--radius", "--tolerance"))
    assert judge(entered, part, "path").code == EXIT_OK
