"""The pencil corner finder against fixtures/pencil_fixtures.json (closed forms of how the
fixtures were built: faces identified by points on them, ball centres R' from both faces)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert

import cadcnc
from cadcnc.core.errors import FaceNumberError
from cadcnc.ops.pencil.corners import BLEND, EDGE, NOT_SELECTED, TANGENT_FACES, find_corners

FIX = Path(__file__).resolve().parents[2] / "fixtures"
SIDECAR = json.loads((FIX / "pencil_fixtures.json").read_text())
CASES = [(name, rp) for name, d in SIDECAR.items() for rp in d["corners_by_offset"]]
_parts: dict = {}


def part_of(name):
    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIX / SIDECAR[name]["file"])
    return _parts[name]


def key(kind, faces, blend_faces=(), edge=None):
    return kind, tuple(faces), tuple(blend_faces), edge


@pytest.mark.parametrize("name,rp", CASES)
def test_corners_found_and_skipped_as_built(name, rp):
    part = part_of(name)
    expected = SIDECAR[name]["corners_by_offset"][rp]
    # split R' = R + C to check the allowance counts
    found = find_corners(part, float(rp) / 2, allowance=float(rp) / 2)
    got = {key(c.kind, c.faces, c.blend_faces, c.edge): c for c in found
           if c.skip != TANGENT_FACES}
    want = {key(e["kind"], e["faces"], e.get("blend_faces", ()), e.get("edge")): e
            for e in expected}
    assert set(got) == set(want)
    for k, e in want.items():
        c = got[k]
        assert c.skip == e["skip"], (k, c.detail)
        if e["kind"] == BLEND:
            assert c.radius == pytest.approx(e["radius"], rel=1e-3)
        if "seeds" in e:
            # each closed-form ball centre is one seed, to 1e-6 mm
            seeds = np.array(c.seeds)
            assert len(seeds) == len(e["seeds"])
            for s in e["seeds"]:
                assert np.linalg.norm(seeds - s, axis=1).min() < 1e-6, (k, s, seeds)
    assert not [c for c in found if c.skip == TANGENT_FACES]  # every tangent edge is a blend's


def test_order_is_by_faces_and_deterministic():
    part = part_of("fillet_pocket")
    a, b = find_corners(part, 3.0), find_corners(part, 3.0)
    assert [c.sort_key() for c in a] == sorted(c.sort_key() for c in a)
    assert [(c.faces, c.blend_faces, c.skip) for c in a] == \
        [(c.faces, c.blend_faces, c.skip) for c in b]


def test_faces_filter_skips_corners_outside_the_set():
    part = part_of("step_slot")
    all_corners = find_corners(part, 3.0)
    first = next(c for c in all_corners if c.kind == EDGE)
    some = find_corners(part, 3.0, faces=first.faces)
    cut = [c for c in some if c.cut]
    assert [(c.faces, c.edge) for c in cut] == [(first.faces, first.edge)]
    others = [c for c in some if c.skip == NOT_SELECTED]
    assert len(others) == sum(c.cut for c in all_corners) - 1
    rec = others[0].skipped()
    assert rec.reason == NOT_SELECTED and rec.edge == others[0].edge + 1


def test_faces_filter_rejects_a_face_out_of_range():
    with pytest.raises(FaceNumberError):
        find_corners(part_of("step_slot"), 3.0, faces=[1, 999])


def test_skipped_blend_names_its_radius_and_the_ball():
    part = part_of("fillet_pocket")
    rolls = [c for c in find_corners(part, 3.0) if c.skip == "blend_rolls"]
    assert rolls and all("5 mm >= R' 3 mm" in c.detail for c in rolls)


@pytest.mark.parametrize("name,rp", [c for c in CASES if c[1] != "1.0"])
def test_every_seed_is_r_prime_from_both_surfaces(name, rp):
    """Independent of the sidecar: OCCT's projection puts each seed R' from faces a, b."""
    part = part_of(name)
    seeds = [(c, s) for c in find_corners(part, float(rp)) if c.kind == BLEND and c.cut
             for s in c.seeds]
    for c, s in seeds:
        for n in c.faces:
            assert part.face(n).project(s, within_face_box=False)[2] == \
                pytest.approx(float(rp), abs=1e-9), (c.faces, n, s)


@pytest.mark.parametrize("rp", SIDECAR["fillet_pocket"]["corners_by_offset"])
def test_blends_found_by_curvature_on_bspline_faces(rp):
    """The fillet pocket with every face converted to a B-spline (same topology): the same
    corners, skips and seeds, so blends are found by curvature, not by surface type."""
    analytic = part_of("fillet_pocket")
    if "nurbs" not in _parts:
        _parts["nurbs"] = cadcnc.Part(BRepBuilderAPI_NurbsConvert(analytic.shape, True).Shape())
    nurbs = _parts["nurbs"]
    assert {f.kind for f in nurbs.faces} == {"bspline"}
    a, b = find_corners(analytic, float(rp)), find_corners(nurbs, float(rp))
    assert [(c.kind, c.faces, c.blend_faces, c.skip) for c in a] == \
        [(c.kind, c.faces, c.blend_faces, c.skip) for c in b]
    assert sum(c.cut for c in b) == sum(e["skip"] is None for e in
                                        SIDECAR["fillet_pocket"]["corners_by_offset"][rp])
    for ca, cb in zip(a, b):
        if ca.cut and ca.kind == BLEND:
            assert np.abs(np.array(ca.seeds) - np.array(cb.seeds)).max() < 1e-6
            assert cb.radius == pytest.approx(ca.radius, rel=1e-3)


BASE = json.loads((FIX / "fixtures.json").read_text())


@pytest.mark.parametrize("name", sorted(BASE))
def test_edge_corners_are_the_concave_edges_of_the_base_fixtures(name):
    """A tiny ball (R' 0.01 mm, nothing tighter) finds one edge corner per concave edge that
    fixtures/build_fixtures.py classified independently (11 samples, ends included)."""
    part = cadcnc.load_step(FIX / BASE[name]["file"])
    want = {}
    for p in BASE[name]["pairs"]:
        inside = p.get("interior_class") if p.get("end_class") == "tangent" else None
        # concave inside and tangent only at its ends counts as concave (docs/method.md)
        n = sum(e["class"] == "concave" or (e["class"] == "mixed" and inside == "concave")
                for e in p["edges"])
        if n:
            want[tuple(sorted(p["faces"]))] = n
    got = {}
    for c in find_corners(part, 0.01):
        if c.kind == EDGE and c.skip is None:
            got[c.faces] = got.get(c.faces, 0) + 1
    assert got == want
