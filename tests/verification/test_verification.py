"""cadcnc.verification: the independent OCCT check of a toolpath (issue 4).

Tolerances used below, and why:
- 1e-9 mm where verify and a closed form compute the same exact distance two ways (OCCT
  projection vs algebra): both are exact to ~1e-12 mm at coordinates of ~50 mm.
- 1e-3 mm gouge: the default pass/fail tolerance of `cadcnc verify` (1 micrometre).
- corruption magnitudes are compared within the uncorrupted path's own worst deviation
  (3e-5 mm on crossing_cylinders at f = 0.1 mm) plus 1e-6 mm.
- the ellipse_pocket 7/8 over-cut is pinned at its measured value within 1 %, so that a
  change in either direction fails.

Paths come from conftest's session cache and reports from this module's cache: both are
shared, never modified (corruptions work on copies).
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

import cadcnc
from cadcnc.core.tolerances import Tolerances
from cadcnc.core.trim_labels import TRIM_STATES
from cadcnc.ops.path.pair_path import intersection_path
from cadcnc.verification import (
    FeedCheck,
    GateResult,
    StopCheck,
    TheoryRow,
    VerificationReport,
    WholePartCheck,
    WholePartHit,
    gouge_gate,
    verify,
)
from cadcnc.verification.probe import FaceProbe
from helpers.fixtures import CONCAVE_PAIRS, FIXTURES, fixture_path, load_fixture

VSIDE = json.loads((FIXTURES / "verification_fixtures.json").read_text())["third_face"]
F = 0.1  # mm per cycle: feed 1500 mm/min, period 4 ms (the paper's numbers)


def radius_for(name: str) -> float:
    """3 mm, except narrow_slot whose 4 mm slot and r=2 hole cannot take a 3 mm ball."""
    return 1.5 if name == "narrow_slot" else 3.0


def path(name, i, j, radius=None):
    """(part, toolpath) at step F, from the session cache (do not modify the toolpath)."""
    r = radius_for(name) if radius is None else radius
    return load_fixture(name), fixture_path(name, i, j, radius=r, feed=F / 0.004 * 60,
                                            period=0.004)


_reports: dict = {}


def verified(name, i, j, radius=None):
    """(part, toolpath, report), verified once per module (do not modify them)."""
    key = (name, i, j, radius)
    if key not in _reports:
        part, tp = path(name, i, j, radius)
        _reports[key] = part, tp, (verify(tp, part) if len(tp) > 1 else None)
    return _reports[key]


def subset(tp, keep):
    """The toolpath restricted to the cycles ``keep`` (bounds included)."""
    b = tuple(dataclasses.replace(s, **{f.name: getattr(s, f.name)[keep]
                                        for f in dataclasses.fields(s)}) for s in tp.bounds)
    return dataclasses.replace(
        tp, points=tp.points[keep], contacts=tp.contacts[keep], normals=tp.normals[keep],
        uv=tp.uv[keep], steps=tp.steps[keep], commanded=tp.commanded[keep], bounds=b)


def closed_form_distance(p, a=23.0, b=13.0):
    """Distance from p to the offset saddle (b cos t, b sin t, sqrt(a^2 - b^2 sin^2 t))."""
    t0, half = np.arctan2(p[1], p[0]), 0.05
    for _ in range(12):  # zoom in on the minimum, 40x each round
        t = np.linspace(t0 - half, t0 + half, 81)
        q = np.stack([b * np.cos(t), b * np.sin(t), np.sqrt(a * a - (b * np.sin(t)) ** 2)], 1)
        d = np.linalg.norm(q - p, axis=1)
        t0, half = t[np.argmin(d)], half / 40
    return d.min()


@pytest.fixture(scope="module")
def cylinders():
    return verified("crossing_cylinders", 1, 2)


# -- agreement with a closed form ---------------------------------------------------------
def test_crossing_cylinders_deviation_matches_closed_form(cylinders):
    _, tp, rep = cylinders
    x, y, z = tp.points.T
    exact = [np.hypot(y, z) - 20.0 - 3.0, np.hypot(x, y) - 10.0 - 3.0]
    for s, e in zip(rep.surfaces, exact):
        assert np.abs(s.deviation - e).max() < 1e-9
        assert np.abs(s.face_deviation - e).max() < 1e-9
    worst_over = max(np.maximum(-e, 0).max() for e in exact)
    worst_under = max(np.maximum(e, 0).max() for e in exact)
    assert rep.max_overcut_mm == pytest.approx(worst_over, abs=1e-9)
    assert rep.max_undercut_mm == pytest.approx(worst_under, abs=1e-9)
    # the offset intersection y^2+z^2 = 23^2, x^2+y^2 = 13^2 is OCCT's branch too
    ref = rep.reference
    assert ref.residual_mm < 1e-7
    d = np.array([closed_form_distance(p) for p in tp.points])
    # OCCT's curve is an approximation within residual_mm of both offset surfaces; the
    # normals meet at 60..90 deg, so it is within ~1.6 x residual of the true curve
    assert np.abs(ref.points_to_branch - d).max() < 2 * ref.residual_mm + 1e-9
    assert ref.coverage == 1.0 and rep.stop.consistent


def test_crossing_cylinders_radius_zero_follows_the_brep_edge():
    part, tp = path("crossing_cylinders", 1, 2, radius=0.0)
    rep = verify(tp, part)
    assert rep.edge_deviation_mm is not None and rep.edge_deviation_mm < 1e-5
    assert rep.hausdorff_mm < 1e-3


# -- every fixture pair -------------------------------------------------------------------
# measured over-cut (mm) where it exceeded the accuracy: a 3 mm ball where R'k reaches 0.9,
# on face 7 (3.1e-3 mm at f = 0.1 with the stepper of commit 889b426; the stepper that
# shortens steps for the chord and the predicted error may bring it within the accuracy)
KNOWN_GOUGES = {("ellipse_pocket", 7, 8): 3.1011870594799262e-3}
# step length off the commanded f by more than 1 % (a finding reported to the interpolator)
KNOWN_FEED = {("ellipse_pocket", 7, 8): 0.049, ("narrow_slot", 11, 12): 0.0146}


@pytest.mark.parametrize("name,i,j", CONCAVE_PAIRS)
def test_every_fixture_pair_verifies(name, i, j):
    part, tp, rep = verified(name, i, j)
    if len(tp) < 2:
        pytest.skip(f"{name} {i}/{j}: no path at radius {radius_for(name)} ({tp.stop_reason})")
    d = rep.to_dict()
    json.dumps(d)
    for key in ("max_overcut_mm", "max_undercut_mm", "hausdorff_mm", "coverage",
                "whole_part_hits"):
        assert key in d
    assert all(s.unseeded_disagreements == 0 for s in rep.surfaces)
    assert rep.reference.residual_mm < 1e-6  # OCCT's curve is a trustworthy reference
    # each centre's distance to OCCT's branch is no larger than its deviation allows
    dev = max(np.abs(s.face_deviation).max() for s in rep.surfaces)
    assert rep.reference.points_max_mm < 10 * dev + 1e-6
    if tp.stop_reason in ("end", "closed"):
        assert rep.coverage > 0.999
    else:
        assert rep.stop.consistent and rep.stop.left_face
    assert rep.feed.max_rel_error < KNOWN_FEED.get((name, i, j), 0.0099) + 0.001
    third = [h for h in rep.whole_part_hits if not h.followed]
    assert third == []
    failed = {c.name for c in rep.verdict}
    if (name, i, j) in KNOWN_GOUGES and rep.max_overcut_mm > rep.tolerances.accuracy:
        # an over-cut beyond the accuracy fails the verdict (deviation), whatever the gouge
        assert rep.max_overcut_mm == rep.max_gouge_mm and not rep.ok(1e-3)
        assert "deviation" in failed and not rep.ok()
        assert ("gouge" in failed) == (rep.max_gouge_mm > rep.tolerances.gouge)
    else:
        assert rep.ok(1e-3), rep.format_table()
        assert failed == set() and rep.ok()


# -- corrupted paths are caught -----------------------------------------------------------
PUSHED = 150  # the cycle pushed 0.01 mm into face 1


@pytest.fixture(scope="module")
def pushed(cylinders):
    part, tp, _ = cylinders
    pts = tp.points.copy()
    pts[PUSHED] -= 0.01 * tp.normals[PUSHED, 0]
    return verify(dataclasses.replace(tp, points=pts), part)


def test_point_pushed_into_a_face_is_caught_at_its_cycle(cylinders, pushed):
    part, tp, clean = cylinders
    k, rep = PUSHED, pushed
    s = rep.surfaces[0]
    assert s.overcut_cycle == k
    assert abs(s.max_overcut_mm - 0.01) < clean.surfaces[0].max_overcut_mm + 1e-6
    assert rep.max_gouge_mm == pytest.approx(s.max_overcut_mm)
    assert not rep.ok(1e-3) and clean.ok(1e-3)
    hit = [h for h in rep.whole_part_hits if h.face == 1][0]
    assert hit.worst_cycle == k


def test_skipped_stretch_on_a_curve_is_caught(cylinders):
    part, tp, clean = cylinders
    keep = np.r_[0:100, 150:len(tp)]
    rep = verify(subset(tp, keep), part)
    gaps = rep.reference.gaps
    assert len(gaps) == 1
    # 50 missing steps = 5 mm; each neighbour covers 0.6 f of it
    assert 5.0 - 1.2 * F - 0.05 < gaps[0][1] - gaps[0][0] < 5.0 + 0.05
    assert rep.coverage < 0.9
    # a 5 mm chord across the gap sags ~ 5^2 / (8 * 13) ~ 0.02 mm off the curve
    assert rep.hausdorff_mm > 100 * clean.hausdorff_mm
    assert rep.feed.worst_cycle == 100 and rep.feed.max_rel_error > 40


def test_skipped_stretch_on_a_straight_edge_is_caught_by_coverage():
    part, tp = path("pocket", 10, 17)
    rep = verify(subset(tp, np.r_[0:50, 80:len(tp)]), part)
    assert rep.hausdorff_mm < 1e-9  # a straight gap cannot show in the Hausdorff distance
    # centres 49 and 80 remain: 31 steps apart, each covers 0.6 f of the gap
    assert rep.coverage == pytest.approx(1 - (31 * F - 1.2 * F) / tp.length, abs=1e-3)


def test_wrong_step_is_caught_by_the_feed_check(cylinders):
    part, tp, clean = cylinders
    k = 200
    pts = tp.points.copy()
    pts[k] += 0.02 * tp.tangents[k]
    rep = verify(dataclasses.replace(tp, points=pts), part)
    assert rep.feed.worst_cycle in (k, k + 1)
    assert rep.feed.max_rel_error == pytest.approx(0.2, abs=2e-3)
    assert clean.feed.max_rel_error < 1e-4


# -- whole-part gouge check --------------------------------------------------------------
@pytest.fixture(scope="module")
def third_face_part():
    return cadcnc.load_step(FIXTURES / VSIDE["file"])


@pytest.mark.parametrize("case", VSIDE["cases"], ids=lambda c: c["name"])
def test_whole_part_check_catches_a_third_face(third_face_part, case):
    part = third_face_part
    tp = intersection_path(*(part.face(n) for n in case["faces"]),
                                  radius=case["radius"], feed=1500, period=0.004)
    rep = verify(tp, part)
    hits = {h.face: h for h in rep.whole_part_hits}
    assert rep.max_overcut_mm < 1e-9  # the pair itself is followed exactly (planes)
    for face, exp in case["hits"].items():
        h = hits[int(face)]
        assert h.depth_mm == pytest.approx(exp["max_depth"], abs=1e-9)
        # closed form: the ball reaches R' - |x - x_wall| into the wall
        expected = np.nonzero(case["radius"] - np.abs(tp.points[:, 0] - exp["plane_x"])
                              > 1e-6)[0]
        assert h.n_cycles == len(expected)
        assert h.cycles[0][0] == expected[0] and h.cycles[-1][1] == expected[-1]
    assert not rep.ok(1e-3)


# -- API details --------------------------------------------------------------------------
def test_part_defaults_to_the_toolpath_source_and_progress_is_called(cylinders):
    _, tp, clean = cylinders
    calls = []
    rep = verify(tp, progress=lambda *a: calls.append(a))
    assert rep.max_overcut_mm == clean.max_overcut_mm
    assert {c[2] for c in calls} >= {"surfaces", "reference", "whole part"}
    text = rep.format_table()
    assert "face 1" in text and "OK" in text


def test_a_thousand_point_path_verifies_in_seconds():
    _, tp, rep = verified("torus_cone", 4, 5)  # the report's own timing of verify
    assert len(tp) > 1000
    assert rep.seconds["total"] < 10.0


# -- the JSON of `cadcnc verify --json` keeps its keys -------------------------------------
# the keys written before the verification package was split (commit 8664f30), in order
OLD_KEYS = {
    "": ["max_overcut_mm", "max_undercut_mm", "hausdorff_mm", "coverage", "whole_part_hits",
         "max_gouge_mm", "faces", "n_points", "radius", "ball_radius", "offsets",
         "stop_reason", "stop_detail", "stop", "surfaces", "reference", "feed", "theory",
         "whole_part", "edge_deviation_mm", "seconds"],
    "surfaces": ["face", "offset", "max_overcut_mm", "overcut_cycle", "max_undercut_mm",
                 "undercut_cycle", "surface_max_overcut_mm", "percentiles_mm",
                 "max_trim_gap_mm", "off_face_cycles", "unseeded_checked",
                 "unseeded_disagreements", "unseeded_max_gain_mm"],
    "percentiles_mm": ["p50", "p95", "p99"],
    "theory": ["face", "measured_overcut_mm", "measured_abs_mm", "eq11_max_mm",
               "eq11_exceeded_overcut", "eq11_exceeded_abs", "eq12_max_mm",
               "eq12_exceeded_overcut", "eq12_exceeded_abs", "eq16_max_mm",
               "eq16_exceeded_overcut", "eq16_exceeded_abs", "worst_ratio_to_eq16",
               "worst_ratio_cycle"],
    "whole_part_hits": ["face", "followed", "depth_mm", "worst_cycle", "n_cycles", "cycles"],
    "reference": ["n_curves", "branch_curves", "occt_seconds", "points_max_mm",
                  "points_worst_cycle", "path_to_branch_mm", "branch_to_path_mm",
                  "hausdorff_mm", "coverage", "cover_radius_mm", "span_mm", "gaps",
                  "residual_mm", "note"],
    "feed": ["max_rel_error", "worst_cycle", "worst_step_mm", "worst_commanded_mm",
             "excluded_last", "last_step_mm", "recorded_vs_measured_mm", "commanded_min_mm",
             "commanded_max_mm", "feed_profile", "feed_min_mm_min", "feed_max_mm_min"],
    "whole_part": ["faces_checked", "distances_evaluated", "ball_radius_mm",
                   "hit_tolerance_mm"],
    "stop": ["reason", "last_contact_states", "span", "remaining_mm", "consistent",
             "left_face"],
    "seconds": ["surfaces", "reference", "whole_part", "total"],
}


# keys added since, after the old ones (issue 9: the swept ball, the verdict, curve coverage
# over the path's own span, material-aware whole-part depth)
NEW_KEYS = {
    "": ["sweep", "ok", "criteria"],
    "reference": ["intended_coverage", "own_span_mm"],
    "whole_part": ["max_depth_mm", "faces_near", "material", "classified"],
}


def test_json_keeps_the_documented_keys(pushed):
    d = json.loads(json.dumps(pushed.to_dict()))
    assert d["whole_part_hits"]  # the pushed point hits face 1: the hit keys are checked
    got = {"": list(d), "surfaces": list(d["surfaces"][0]),
           "percentiles_mm": list(d["surfaces"][0]["percentiles_mm"]),
           "theory": list(d["theory"][0]), "whole_part_hits": list(d["whole_part_hits"][0]),
           **{k: list(d[k]) for k in ("reference", "feed", "whole_part", "stop", "seconds")}}
    assert got == {k: v + NEW_KEYS.get(k, []) for k, v in OLD_KEYS.items()}
    assert [c["name"] for c in d["criteria"]] == ["gouge", "deviation", "hausdorff",
                                                  "coverage"]
    assert all(list(s) == OLD_KEYS["surfaces"] for s in d["surfaces"])
    assert all(list(t) == OLD_KEYS["theory"] for t in d["theory"])


def test_the_report_is_typed(cylinders, pushed):
    _, _, rep = cylinders
    assert isinstance(rep, VerificationReport) and isinstance(rep.feed, FeedCheck)
    assert isinstance(rep.stop, StopCheck) and isinstance(rep.whole_part, WholePartCheck)
    assert all(isinstance(t, TheoryRow) and t.has_bounds for t in rep.theory)
    assert all(isinstance(h, WholePartHit) for h in pushed.whole_part_hits)
    assert set(rep.stop.last_contact_states) <= set(TRIM_STATES)
    assert all(set(s.states) <= set(TRIM_STATES) for s in rep.surfaces)
    assert rep.tolerances == Tolerances() and rep.whole_part.hit_tolerance_mm == 1e-6
    assert rep.ok() == rep.ok(1e-3) and not pushed.ok()


# -- the whole-part gouge gate ------------------------------------------------------------
def test_gate_passes_a_clean_pair_and_agrees_with_verify(cylinders):
    part, tp, rep = cylinders
    gate = gouge_gate(tp, part)
    assert isinstance(gate, GateResult)
    assert gate.ok and gate.message == "" and gate.limit_mm == 1e-3
    assert gate.depth_mm == rep.max_gouge_mm and gate.hits == rep.whole_part_hits


def test_gate_skips_the_occt_reference(cylinders, monkeypatch):
    part, tp, _ = cylinders

    def no_reference(*a, **k):
        raise AssertionError("the gate must not intersect the offset surfaces")

    monkeypatch.setattr("cadcnc.verification.probe.intersect", no_reference)
    assert gouge_gate(tp, part).ok


def test_gate_uses_the_given_or_the_job_tolerances(cylinders):
    part, tp, rep = cylinders
    strict = Tolerances(gouge=1e-6)
    gate = gouge_gate(tp, part, strict)
    # under the stricter limit the gate examines the moves between the points and finds
    # the chords deeper than the centres (verify bounds them within the default limit)
    assert not gate.ok and gate.limit_mm == 1e-6 and gate.depth_mm >= rep.max_gouge_mm
    assert gate.message.startswith("refused: the ball cuts into the part (face ")
    job_tp = dataclasses.replace(tp, job=dataclasses.replace(tp.job, tolerances=strict))
    assert gouge_gate(job_tp, part).message == gate.message


def test_gate_refuses_a_ball_too_big_for_the_slot():
    part, tp = path("narrow_slot", 3, 4, radius=3.0)
    gate = gouge_gate(tp, part)
    assert not gate.ok and gate.depth_mm == pytest.approx(2.0, abs=1e-9)
    assert "face 5 by 2 mm over 601 cycles" in gate.message
    assert gate.message.startswith("refused: the ball cuts into the part (")
    assert gate.message.endswith(") beyond 0.001 mm; nothing written")
    assert {h.face for h in gate.hits} == {1, 5, 6, 10}


def test_gate_fails_closed_when_the_check_raises(cylinders, monkeypatch):
    part, tp, _ = cylinders

    def broken(self, point):
        raise RuntimeError("OCCT said no")

    monkeypatch.setattr(FaceProbe, "face_distance", broken)
    # the bounded gate needs no DistShapeShape on this path: its global projections fail too
    monkeypatch.setattr(FaceProbe, "project_global", lambda self, p, *a: broken(self, p))
    gate = gouge_gate(tp, part)
    assert not gate.ok and math.isnan(gate.depth_mm)
    assert "could not be completed" in gate.message and "OCCT said no" in gate.message


def test_gate_fails_closed_on_an_unmeasured_distance(cylinders, monkeypatch):
    part, tp, _ = cylinders
    seeded = FaceProbe.project_seeded

    def nan_distance(self, point, u0, w0):
        u, w, _ = seeded(self, point, u0, w0)
        return u, w, math.nan

    monkeypatch.setattr(FaceProbe, "project_seeded", nan_distance)
    gate = gouge_gate(tp, part)
    assert not gate.ok and math.isnan(gate.depth_mm)
    assert "could not be completed" in gate.message and "could not be measured" in gate.message


def test_gate_fails_closed_on_a_nan_distance_to_another_face(monkeypatch):
    part, tp = path("narrow_slot", 3, 4)  # R 1.5: clean, the end faces are near the ball
    assert gouge_gate(tp, part).ok
    monkeypatch.setattr(FaceProbe, "face_distance", lambda self, p: (math.nan, math.nan))
    # the closed form on planes asks no DistShapeShape: the nan must come from OCCT's
    monkeypatch.setattr(FaceProbe, "plane_distance", lambda self, p: None)
    gate = gouge_gate(tp, part)
    assert not gate.ok and any(not h.followed and math.isnan(h.depth_mm) for h in gate.hits)
    assert "could not be measured" in gate.message
