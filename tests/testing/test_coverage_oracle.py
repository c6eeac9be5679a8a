"""The coverage benchmark's judge (cadcnc/testing/coverage_oracle.py) against closed forms.

The judge decides which ball positions are feasible along concave edges; coverage figures
are only as good as it is. On the pocket fixture the floor (z = 15) meets the planar wall
x = -30: every feasible centre sits at R' from both planes, (-30 + R', y, 15 + R'). In the
4 mm slot a 6 mm ball has no feasible position (the opposite wall is nearer than R').
Planes and offsets come from fixtures/fixtures.json, not from this file.
"""

import json
from pathlib import Path

import numpy as np
import pytest

from benchmarks.coverage import coverage_paths as _paths
from cadcnc.testing import coverage_oracle as _oracle

ROOT = Path(__file__).resolve().parents[2]


Oracle, read_shape = _oracle.Oracle, _oracle.read_shape
classify, cut_polylines = _paths.classify, _paths.cut_polylines
distance_to_polylines = _paths.distance_to_polylines

FACTS = json.loads((ROOT / "fixtures" / "fixtures.json").read_text())


def _plane(fixture: str, role_start: str) -> tuple[int, np.ndarray, float]:
    for n, f in FACTS[fixture]["faces"].items():
        if f["role"].startswith(role_start):
            return int(n), np.array(f["normal"]), f["offset"]
    raise AssertionError(f"{fixture}: no face {role_start!r}")


@pytest.fixture(scope="module")
def pocket():
    return Oracle(read_shape(str(ROOT / "fixtures" / "pocket.step")))


@pytest.mark.parametrize("radius", [2.0, 5.0])
def test_floor_wall_corner_centres_sit_at_r_from_both_planes(pocket, radius):
    wall, n_wall, d_wall = _plane("pocket", "pocket planar wall x=-30")
    floor, n_floor, d_floor = _plane("pocket", "pocket floor z=15")
    (edge,) = [e for e in pocket.concave_edges() if e.faces == tuple(sorted((wall, floor)))]
    assert abs(edge.angles - 270.0).max() < 1e-6
    ts = pocket.samples(edge, cap=15)
    assert len(ts) == 15
    verdicts = [pocket.judge(edge, t, radius, 10 * radius) for t in ts]
    assert {v["verdict"] for v in verdicts} == {"feasible"}
    p = np.array([v["p"] for v in verdicts])
    assert np.abs(p @ n_wall - d_wall - radius).max() < 1e-6
    assert np.abs(p @ n_floor - d_floor - radius).max() < 1e-6
    # the samples cover the edge: y from one end of the 24 mm straight wall to the other
    assert np.ptp(p[:, 1]) == pytest.approx(edge.length, abs=1e-6)


def test_a_slot_narrower_than_the_ball_has_no_feasible_position():
    slot = Oracle(read_shape(str(ROOT / "fixtures" / "narrow_slot.step")))
    floor, *_ = _plane("narrow_slot", "slot floor")
    wall, *_ = _plane("narrow_slot", "slot wall y=-10")
    other, *_ = _plane("narrow_slot", "slot wall y=-6")
    (edge,) = [e for e in slot.concave_edges() if e.faces == tuple(sorted((wall, floor)))]
    ts = slot.samples(edge, cap=9)
    wide = [slot.judge(edge, t, 3.0, 30.0) for t in ts]   # 2R' = 6 > 4 mm
    assert {v["verdict"] for v in wide} == {"nearer"}
    # inside the slot the opposite wall is 1 mm away; at the slot's open ends the block's
    # end face (its notch's edge) is equally near and may be named instead
    assert {v["face"] for v in wide[1:-1]} == {other}
    fits = [slot.judge(edge, t, 1.5, 15.0) for t in ts]   # 2R' = 3 < 4 mm
    assert {v["verdict"] for v in fits} == {"feasible"}


def test_coverage_distance_and_formats():
    line = np.array([[0.0, 0, 0], [10, 0, 0]])
    pts = np.array([[5.0, 0.004, 0], [5.0, 0, 0.006], [-1.0, 0, 0]])
    assert np.allclose(distance_to_polylines(pts, [line]), [0.004, 0.006, 1.0])
    v2 = {"format": "cadcnc-program", "version": 2,
          "segments": [{"kind": "cut", "points": line.tolist()},
                       {"kind": "link", "points": [[0, 0, 50]]},
                       {"kind": "cut", "points": [[1, 1, 1], [2, 2, 2]]}]}
    assert [len(x) for x in cut_polylines(v2)] == [2, 2]
    assert [len(x) for x in cut_polylines({"version": 1, "points": line.tolist()})] == [2]
    assert classify(1, "Traceback (most recent call last):\n ...") == "crash"
    assert classify(3, "cadcnc: error: x.step: holds no solid") == "no solid in the file"
    assert classify(None, "") == "timeout"


@pytest.mark.parametrize("fixture", ["bspline_boss", "dome_pole"])
def test_edge_angles_agree_with_the_fixture_sidecar(fixture):
    """The judge's material angles (interior samples) lie in the sidecar's sampled range,
    B-spline faces (non-orthogonal parameters) included."""
    judge = Oracle(read_shape(str(ROOT / "fixtures" / f"{fixture}.step")))
    by_index = {e.index: e for e in judge.edges}
    checked = 0
    for pair in FACTS[fixture]["pairs"]:
        for e in pair["edges"]:
            lo, hi = e["material_angle_deg"]
            angles = by_index[e["edge"]].angles
            assert lo - 1e-3 <= angles.min() and angles.max() <= hi + 1e-3, (pair["faces"], e)
            assert by_index[e["edge"]].concave == (e["class"] == "concave")
            checked += 1
    assert checked >= 10


def test_api_mode_runs_the_pair_runner_with_the_period_in_seconds():
    """``--via api`` runs benchmarks/coverage_run_pair.py (which exists) with the period
    converted to seconds; refusals from the stretch finder get their own reason."""
    assert _paths.period_seconds("4ms") == pytest.approx(0.004)
    assert _paths.period_seconds("250us") == pytest.approx(2.5e-4)
    assert _paths.period_seconds("0.01") == pytest.approx(0.01)
    with pytest.raises(ValueError):
        _paths.period_seconds("fast")
    cmd = _paths.path_command("a.step", (3, 4), 2.0, 1500.0, "4ms", "o.json", None, "api")
    assert Path(cmd[1]).name == "coverage_run_pair.py" and Path(cmd[1]).is_file()
    assert cmd[2:] == ["a.step", "3", "4", "2.0", "1500.0", "0.004", "o.json"]
    assert "path" in _paths.path_command("a.step", (3, 4), 2.0, 1500.0, "4ms", "o.json", 2,
                                         "cli")
    msg = "cadcnc: path: faces 3 and 4: no feasible ball position along their shared " \
          "concave edge(s): edge 1: the ball touches face 4 outside the face"
    assert classify(2, msg) == "no feasible position (stretch finder)"


def test_face_distance_closed_form_and_the_classifier_correction(pocket, monkeypatch):
    """Pocket floor (z = 15, the pocket spans x -30..30): 3 mm above its middle the
    distance is 3; above (-40, 0), outside the pocket, the foot is off the face and the
    distance is to the floor's edge x = -30, sqrt(10^2 + 3^2). When BRepExtrema overstates
    a distance (its classifier calling an inside foot OUT), the foot on the face replaces
    it and is counted; a foot off the face never does."""
    floor, *_ = _plane("pocket", "pocket floor z=15")
    inside, outside = np.array([0.0, 0.0, 18.0]), np.array([-40.0, 0.0, 18.0])
    pocket.corrections.clear()
    assert pocket.face_distance(inside, floor) == pytest.approx(3.0, abs=1e-9)
    assert pocket.face_distance(outside, floor) == pytest.approx(np.sqrt(109.0), abs=1e-9)
    assert pocket.corrections == []

    real = _oracle.BRepExtrema_DistShapeShape

    class Overstated:  # BRepExtrema answering 1 mm too far, as at a degenerate ray
        def __init__(self, a, b):
            self.d = real(a, b)

        def IsDone(self):
            return self.d.IsDone()

        def Value(self):
            return self.d.Value() + 1.0

    monkeypatch.setattr(_oracle, "BRepExtrema_DistShapeShape", Overstated)
    assert pocket.face_distance(inside, floor) == pytest.approx(3.0, abs=1e-9)
    assert pocket.face_distance(outside, floor) == pytest.approx(np.sqrt(109.0) + 1.0)
    assert [c["face"] for c in pocket.corrections] == [floor]
    assert pocket.clearance(inside, 3.5)[0] <= 3.0 + 1e-9
    pocket.corrections.clear()


def test_surface_models_are_sewn_with_the_files_face_numbers():
    """The same part as a solid, a closed shell and loose faces (two of them reversed in
    the file): the judge sews the loose faces, keeps the file's numbers, and finds the same
    concave edge with the same verdicts and centres. The open sheet's floor points down in
    the file: its material side is chosen so that most of the area faces +Z, which makes
    the floor-wall corner concave (270 deg)."""
    judged = {}
    for name in ("surf_boss_solid", "surf_boss_shell", "surf_boss_faces"):
        o = Oracle(read_shape(str(ROOT / "fixtures" / f"{name}.step")))
        (edge,) = o.concave_edges()
        judged[name] = (o.rules, edge.faces, [o.judge(edge, t, 2.0, 20.0)
                                              for t in o.samples(edge, cap=9)])
    assert [judged[n][0] for n in judged] == [["solid"], ["closed shell"], ["closed shell"]]
    solid = judged["surf_boss_solid"]
    for name in ("surf_boss_shell", "surf_boss_faces"):
        assert judged[name][1] == solid[1] == (4, 5)
        assert [v["verdict"] for v in judged[name][2]] == [v["verdict"] for v in solid[2]]
        assert np.abs(np.array([v["p"] for v in judged[name][2]])
                      - [v["p"] for v in solid[2]]).max() < 1e-9
    sheet = Oracle(read_shape(str(ROOT / "fixtures" / "surf_sheet.step")))
    (edge,) = sheet.concave_edges()
    assert sheet.rules == ["open shell, flipped"] and edge.faces == (1, 2)
    assert abs(edge.angles - 270.0).max() < 1.0
