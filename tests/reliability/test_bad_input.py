"""Bad input gets one clear line and a non-zero exit, never a traceback or a bad file.

Each case is a defect found by attacking the tool as a hostile user would (issue 9):
it failed before the fix.
"""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import FaceNumberError, StepFileError
from cadcnc.core.job import Job, PairPath, Tool
from cadcnc.ops.path.pair_path import intersection_path
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES, load_fixture

BOSS = FIXTURES / "bspline_boss.step"
JOB = ["--radius", "3", "--feed", "1500", "--period", "4ms"]


def one_line_error(run, code: int, *needles: str) -> None:
    assert run.returncode == code, (run.returncode, run.stderr)
    assert run.stderr.startswith("cadcnc: error: "), run.stderr
    assert "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1
    for needle in needles:
        assert needle in run.stderr, run.stderr


@pytest.mark.parametrize("flag, value, needle", [
    ("--clearance", "nan", "--clearance"), ("--safe-z", "inf", "--clearance"),
    ("--spindle", "nan", "--spindle"), ("--spindle", "-100", "--spindle"),
    ("--spindle", "inf", "--spindle"), ("--gouge-tolerance", "abc", "gouge tolerance"),
    ("--gouge-tolerance", "nan", "gouge tolerance"), ("--gouge-tolerance", "-1", "gouge"),
    ("--gouge-tolerance", "inf", "'inf' is not a finite number"),
    ("--gouge-tolerance", "-Infinity", "is not a finite number"),
])
def test_non_finite_and_negative_options_are_refused(tmp_path, flag, value, needle):
    out = tmp_path / "p.ngc"
    run = cadcnc_cli("path", BOSS, "--faces", "4", "5", *JOB, "-o", out, f"{flag}={value}")
    one_line_error(run, 2, needle)
    assert not out.exists()


def test_a_feed_that_prints_as_f0_is_refused(tmp_path):
    out = tmp_path / "p.ngc"
    run = cadcnc_cli("path", BOSS, "--faces", "4", "5", "--radius", "3", "--feed", "0.0004",
                     "--period", "1000s", "-o", out, "--allow-gouge")
    assert run.returncode != 0 and "F0" in run.stderr and not out.exists()


def test_negative_start_coordinates_need_no_equals_sign(tmp_path):
    args = ["path", FIXTURES / "crossing_cylinders.step", "--faces", "1", "2", *JOB,
            "-o", tmp_path / "p.json"]
    plain = cadcnc_cli(*args, "--start", "-6,6,5", "--quiet")
    joined = cadcnc_cli(*args, "--start=-6,6,5", "--quiet")
    assert "expected one argument" not in plain.stderr
    assert (plain.returncode, plain.stderr) == (joined.returncode, joined.stderr)


def test_edge_number_is_reported_as_the_user_counts(tmp_path):
    run = cadcnc_cli("path", BOSS, "--faces", "4", "5", *JOB, "--edge", "2",
                     "-o", tmp_path / "p.json")
    one_line_error(run, 2, "there is no edge 2")


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their mode")
def test_unreadable_step_is_a_clear_error(tmp_path):
    f = tmp_path / "locked.step"
    f.write_bytes(BOSS.read_bytes())
    f.chmod(0)
    for command in (["faces", f], ["path", f, "--faces", "4", "5", *JOB, "-o",
                                   tmp_path / "p.json"]):
        one_line_error(cadcnc_cli(*command), 2, "cannot read")


def test_unreadable_step_is_a_clear_error_even_as_root(tmp_path, monkeypatch):
    f = tmp_path / "locked.step"
    f.write_bytes(BOSS.read_bytes())
    real_open = open

    def deny(path, *a, **k):
        if str(path) == str(f):
            raise PermissionError(13, "Permission denied")
        return real_open(path, *a, **k)

    monkeypatch.setattr("builtins.open", deny)
    with pytest.raises(StepFileError, match="cannot read"):
        cadcnc.load_step(f)


def test_step_with_bom_or_leading_comment_is_read(tmp_path):
    text = BOSS.read_bytes()
    for name, data in (("bom.step", b"\xef\xbb\xbf" + text),
                       ("comment.step", b"/* exported by a test */\n" + text)):
        (tmp_path / name).write_bytes(data)
        assert len(cadcnc.load_step(tmp_path / name)) == len(load_fixture("bspline_boss"))


def test_faces_json_stays_json_when_occt_complains(tmp_path):
    """OCCT prints reader errors on stdout; they go to stderr and the JSON's warnings."""
    text = (FIXTURES / "pocket.step").read_text()
    end = text.index("ENDSEC;", text.index("DATA;"))
    bad = tmp_path / "unresolved.step"
    bad.write_text(text[:end] + "#99990=VERTEX_POINT('',#99991);\n" + text[end:])
    run = cadcnc_cli("faces", bad, "--json")
    data = json.loads(run.stdout)
    assert data["n_faces"] == 17
    assert any("Unresolved Reference" in w for w in data["warnings"])
    assert "Unresolved Reference" in run.stderr


def test_api_refuses_mistakes_with_clear_errors():
    part = load_fixture("bspline_boss")
    floor, boss = part.face(4), part.face(5)
    kw = dict(radius=3, feed=1500, period=0.004)
    with pytest.raises(cadcnc.InputError, match="radius"):
        intersection_path(floor, boss, **{**kw, "radius": True})
    with pytest.raises(cadcnc.InputError, match="start must be a point"):
        intersection_path(floor, boss, start="1,2,3", **kw)
    with pytest.raises(cadcnc.InputError, match="edge"):
        intersection_path(floor, boss, edge=-1, **kw)
    with pytest.raises(cadcnc.InputError, match="edge"):
        intersection_path(floor, boss, edge="1", **kw)
    with pytest.raises(FaceNumberError, match="True"):
        part.face(True)
    with pytest.raises(cadcnc.InputError, match="finite"):
        floor.normal(float("nan"), float("nan"))
    import numpy as np

    a = intersection_path(floor, boss, **{**kw, "feed": np.int64(1500)})
    b = intersection_path(floor, boss, **{**kw, "feed": np.float32(1500)})
    assert (a.points == b.points).all()


def test_cadquery_objects_that_are_not_solids_get_a_clear_error():
    import cadquery as cq

    box = cq.Workplane().box(10, 10, 10)
    assembly = cq.Assembly().add(box)
    assert len(cadcnc.Part.from_cadquery(assembly)) == 6
    with pytest.raises(StepFileError, match="Sketch"):
        cadcnc.Part.from_cadquery(cq.Sketch().rect(1, 1))


def test_job_is_validated_where_it_is_built():
    with pytest.raises(cadcnc.InputError, match="feed"):
        Job(Tool(3.0), feed=float("nan"), period=0.004)
    with pytest.raises(cadcnc.InputError, match="end point needs a start"):
        PairPath(end=(0, 0, 0))
    with pytest.raises(cadcnc.InputError, match="clearance"):
        Job(Tool(3.0), 1500.0, 0.004, clearance=float("inf"))
    assert Tool(3.0).shank == 30.0 and Job(Tool(3.0), 1500, 0.004).step == pytest.approx(0.1)


def test_a_point_beyond_the_faces_edges_projects_to_the_nearest_point_of_the_face():
    """GeomAPI finds no interior extremum there; the fallback is the trimmed face's
    nearest point. Closed form: the boss (r 8 about (5, -3), top z 45) seen from
    (15, -3, 50) is nearest at its top rim (13, -3, 45), sqrt(29) mm away."""
    boss = load_fixture("bspline_boss").face(5)
    u, w, d = boss.project((15, -3, 50))
    assert d == pytest.approx(29 ** 0.5, abs=1e-9)
    assert boss.point(u, w) == pytest.approx([13, -3, 45], abs=1e-9)
    with pytest.raises(cadcnc.InputError, match=r"\(nan, 1.0, 2.0\)"):
        boss.project((float("nan"), 1, 2))


@pytest.mark.parametrize("z", [19.0, 17.0])
def test_a_start_point_near_an_edge_is_accepted(z):
    """Was: 'no projection of point (np.float64(...)) found' for a start 0.2 mm outside
    the boss (99 of 130 API fuzz refusals). The path goes once around, as from the edge."""
    part = load_fixture("bspline_boss")
    path = intersection_path(part.face(4), part.face(5), radius=3, feed=1500,
                                    period=0.004, start=(13.2, -3.0, z))
    assert path.complete, path.stop_reason
    assert path.stop_reason == "closed"
    length = float(np.linalg.norm(np.diff(path.points, axis=0), axis=1).sum())
    assert length > 2 * np.pi * 8
