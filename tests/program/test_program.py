"""The program of linked moves: links, totals, JSON version 2 round trip, version 1 read."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cadcnc.core.errors import InputError
from cadcnc.io.program_json import program_to_dict, read_program, write_program_json
from cadcnc.io.toolpath_json import write_json
from cadcnc.program.linking import APPROACH, link, linked
from cadcnc.program.program import CutSegment, Program, Skipped
from helpers.fixtures import fixture_path
from helpers.programs import assert_same_path


@pytest.fixture(scope="module")
def two_cuts():
    """Two floor-to-wall corners of the pocket: two separate cuts."""
    return [fixture_path("pocket", i, 17) for i in (8, 12)]


def test_link_retracts_rapids_and_plunges():
    a, b = np.array([0.0, 0.0, 1.0]), np.array([10.0, 5.0, -2.0])
    ln = link(a, b, z_safe=20.0)
    np.testing.assert_array_equal(ln.points, [a, [0, 0, 20], [10, 5, 20],
                                              [10, 5, -2 + APPROACH], b])
    assert ln.rapid.tolist() == [True, True, True, False]
    assert ln.feed_length == pytest.approx(APPROACH)
    assert ln.length == pytest.approx(19 + np.hypot(10, 5) + 22)


def test_linked_program_order_and_totals(two_cuts):
    cuts = [CutSegment(p, edge=k + 1) for k, p in enumerate(two_cuts)]
    z = 60.0
    prog = Program(two_cuts[0].job, linked(cuts, z), [Skipped((1, 2), "too short", "x")])
    kinds = [s.kind for s in prog.segments]
    assert kinds == ["link", "cut", "link", "cut", "link"]
    moves = prog.all_moves()
    # consecutive segments join: every link starts where the previous cut ended
    for before, after in zip(prog.segments, prog.segments[1:]):
        np.testing.assert_array_equal(before.points[-1], after.points[0])
    assert moves[:, 2].max() == pytest.approx(z)
    assert prog.cut_length == pytest.approx(sum(p.length for p in two_cuts))
    feed_s = sum(p.duration for p in two_cuts) + 2 * APPROACH / prog.job.feed * 60
    assert prog.time_at_feed == pytest.approx(feed_s)
    assert prog.complete == all(p.complete for p in two_cuts)


def test_joined_cuts_need_no_link(two_cuts):
    p = two_cuts[0]
    assert [s.kind for s in linked([CutSegment(p), CutSegment(p)], 99.0)].count("link") == 3
    # the saddle's two edges meet end to start: one continuous cut, no link between
    halves = [CutSegment(fixture_path("crossing_cylinders", 1, 2, edge=k)) for k in (0, 1)]
    assert [s.kind for s in linked(halves, 99.0)] == ["link", "cut", "cut", "link"]


def test_program_json_round_trip(two_cuts, tmp_path):
    cuts = [CutSegment(p, edge=k + 1, stretch=1) for k, p in enumerate(two_cuts)]
    prog = Program(two_cuts[0].job, linked(cuts, 60.0),
                   [Skipped((3, 4), "tangent", "faces meet along a tangent edge", 2)])
    out = tmp_path / "prog.json"
    write_program_json(prog, out)
    d = json.loads(out.read_text())
    assert (d["format"], d["version"]) == ("cadcnc-program", 2)
    assert [s["kind"] for s in d["segments"]] == ["link", "cut", "link", "cut", "link"]
    assert d["segments"][1]["faces"] == [8, 17] and d["segments"][1]["edge"] == 1
    back = read_program(out)
    assert back.skipped == prog.skipped
    for a, b in zip(back.segments, prog.segments):
        assert a.kind == b.kind
        if a.kind == "cut":
            assert_same_path(a.path, b.path)
            assert (a.edge, a.stretch) == (b.edge, b.stretch)
        else:
            np.testing.assert_array_equal(a.points, b.points)
            np.testing.assert_array_equal(a.rapid, b.rapid)
    assert d["summary"]["cuts"] == 2 and d["summary"]["links"] == 3


def test_version_1_reads_as_a_program_of_one_cut(two_cuts, tmp_path):
    out = tmp_path / "v1.json"
    write_json(two_cuts[0], out)
    prog = read_program(out)
    assert len(prog.segments) == 1 and prog.cuts[0].edge == 1
    assert_same_path(prog.paths[0], two_cuts[0])


@pytest.mark.parametrize("change, message", [
    (lambda d: d.update(version=3), "version 3 is not supported"),
    (lambda d: d.update(format="x"), "not a cadcnc program"),
    (lambda d: d["segments"][0].update(kind="jump"), "segment 1: kind must be"),
    (lambda d: d["segments"][0]["points"][0].__setitem__(0, "NaN"), "non-finite"),
    (lambda d: d["segments"][1].pop("uv"), r"segment 2 \(cut\)"),
    (lambda d: d.update(segments=[], skipped=[]), "no cut segment"),
])
def test_program_json_errors(two_cuts, tmp_path, change, message):
    prog = Program(two_cuts[0].job, linked([CutSegment(two_cuts[0])], 60.0))
    d = json.loads(json.dumps(program_to_dict(prog)))
    change(d)
    f = tmp_path / "bad.json"
    f.write_text(json.dumps(d))
    with pytest.raises(InputError, match=message):
        read_program(f)


def test_program_gcode_moves_are_the_programs(two_cuts):
    """Every move written, parsed back, is the program's own sequence of points."""
    from cadcnc.io.gcode import programmed_moves
    from cadcnc.io.program_gcode import program_ngc

    prog = Program(two_cuts[0].job, linked([CutSegment(p) for p in two_cuts], 60.0))
    text = program_ngc(prog, plunge_feed=300.0)
    moves = programmed_moves(text)
    want = [prog.segments[0].points[0]]
    for seg in prog.segments:
        want += list(seg.points[1:])
    np.testing.assert_allclose(moves, np.array(want), rtol=0, atol=0.5e-4 * np.sqrt(3))
    assert text.count("F300") == 2 and "G0 X" in text and text.rstrip().endswith("%")
    tip = programmed_moves(program_ngc(prog, tool_tip=True), tool_tip_offset=3.0)
    np.testing.assert_allclose(tip, moves, atol=1e-4)


def test_rs274_reads_the_program_moves(two_cuts, tmp_path):
    """rs274 executes every feed and rapid move of a linked program, at the program's points."""
    import re
    import subprocess

    from cadcnc.io.program_gcode import program_ngc
    from cadcnc.testing.rs274 import DECIMALS as RS274_DECIMALS
    from cadcnc.testing.rs274 import RS274

    if RS274 is None:
        pytest.skip("LinuxCNC rs274 not installed")
    prog = Program(two_cuts[0].job, linked([CutSegment(p) for p in two_cuts], 60.0))
    src, out = tmp_path / "p.ngc", tmp_path / "canon.txt"
    src.write_text(program_ngc(prog, plunge_feed=300.0))
    run = subprocess.run([RS274, "-g", str(src), str(out)], capture_output=True, text=True,
                         timeout=60)
    assert run.returncode == 0, run.stderr
    canon = out.read_text()
    moves = np.array([[float(v) for v in m.group(2).split(",")[:3]] for m in re.finditer(
        r"STRAIGHT_(FEED|TRAVERSE)\(([^)]*)\)", canon)])
    want = [prog.segments[0].points[0]]
    for seg in prog.segments:
        want += list(seg.points[1:])
    # the first rapid gives Z only (X, Y from the machine's start): compare from the second
    np.testing.assert_allclose(moves[1:], np.array(want), rtol=0,
                               atol=0.5 * 10.0 ** -RS274_DECIMALS + 1e-9)


@pytest.mark.parametrize("suffix", [".png", ".glb"])
def test_program_pictures(two_cuts, tmp_path, suffix):
    """The picture shows the part, one line per cut and the links."""
    from cadcnc.io.program_plot import program_scene, write_program_picture
    from helpers.fixtures import load_fixture

    part = load_fixture("pocket")
    prog = Program(two_cuts[0].job, linked([CutSegment(p) for p in two_cuts], 60.0))
    out = tmp_path / f"p{suffix}"
    write_program_picture(prog, part, out, title="pocket")
    magic = b"\x89PNG\r\n\x1a\n" if suffix == ".png" else b"glTF"
    assert out.read_bytes().startswith(magic)
    if suffix == ".glb":
        names = set(program_scene(prog, part).geometry)
        assert {"cut2", "cut4", "link1", "link3", "link5"} <= names
        assert sum(n.startswith("face") for n in names) == len(part.faces)
