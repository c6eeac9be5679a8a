"""Steep-shallow keeps every scallop within --scallop, the faces' edges included: the
samples on a face's boundary are found (not its seam), the boundaries running along the
raster planes get half the spacing (a pass whose contact leaves the face there is missing
over a long stretch, so the edge is cut from the next plane inside only), and the union's
uncut report of the free-form wall stays at or below the limit."""

from __future__ import annotations

import functools
import json

import numpy as np
import pytest

import cadcnc
from cadcnc.ops.finish import steep_shallow
from cadcnc.ops.finish.plan import across, along_edges, centre_chord, plan_planes, sample_faces
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "waterline_fixtures.json").read_text())


@functools.cache
def part(name: str):
    """A waterline fixture's part, read once."""
    return cadcnc.load_step(FIXTURES / FACTS[name]["file"])


def test_edge_samples_are_the_fillets_two_circles_not_its_seam():
    """The boss's fillet (a torus, periodic round the axis): its boundary is the foot
    circle (r 11, z 5) and the circle on the wall (r 8, z 8); the seam is no boundary."""
    fillet = FACTS["boss"]["fillet"]
    s = sample_faces(part("boss"), [fillet], 0.5)
    r, z = np.hypot(s.points[:, 0], s.points[:, 1]), s.points[:, 2]
    foot = (np.abs(r - 11.0) < 1e-6) & (np.abs(z - 5.0) < 1e-6)
    top = (np.abs(r - 8.0) < 1e-6) & (np.abs(z - 8.0) < 1e-6)
    assert foot.sum() >= 20 and top.sum() >= 20
    assert np.array_equal(s.edge, foot | top)


def test_the_walls_edges_along_the_planes_get_half_the_spacing():
    """The free-form wall (x -20..20, y -10..10), planes across y (angle 0): its edges
    y = +-10 run along the planes, x = +-20 across them; every gentle sample of the y edges
    has a plane within half its own chord on the face's side, so the edge's cusp is
    within H even where the plane beyond it has left the face."""
    wall = FACTS["wall"]["faces"]
    s = sample_faces(part("wall"), wall, 0.5)
    n = np.array([0.0, 1.0, 0.0])
    f = (s.points + 3.0 * s.normals) @ n
    along, slope = along_edges(s, f, across(s, n)[1])
    on_y = s.edge & (np.abs(np.abs(s.points[:, 1]) - 10.0) < 1e-6)
    on_x = s.edge & (np.abs(np.abs(s.points[:, 0]) - 20.0) < 1e-6)
    assert on_y.sum() > 100 and on_x.sum() > 20
    gentle = s.normals[:, 2] >= 0.5   # at most 60 deg steep (steeper edges: no rule)
    assert (along[on_y & ~on_x & gentle] != 0).all()   # (the corners either way)
    assert not along[~gentle].any()
    assert not along[on_x & ~on_y].any()
    assert (along[on_y & (s.points[:, 1] < 0)] >= 0).all()   # the face lies towards +y
    assert (along[on_y & (s.points[:, 1] > 0)] <= 0).all()
    h = 0.05
    plan = plan_planes(s, 3.0, 0.0, 0.0, scallop=h)
    k, g = across(s, n)
    chord = centre_chord(h, k, 3.0) * g
    planes = np.sort(plan.offsets)
    served = 0
    for i in np.flatnonzero((along != 0) & (plan.reason == "")):
        inward = planes[planes >= f[i]] - f[i] if along[i] > 0 else f[i] - planes[planes <= f[i]]
        assert len(inward) and inward.min() <= 0.5 * chord[i] + 1e-9
        served += 1
    assert served > 100


@pytest.mark.parametrize("name, radius, faces, scallop", [
    ("wall", 3.0, FACTS["wall"]["faces"], 0.2),
])
def test_steep_shallow_union_is_within_the_scallop(monkeypatch, name, radius, faces, scallop):
    """The one uncut report of the union (steep samples across the levels, shallow ones
    across the planes): largest scallop at or below the limit, nothing over it, nothing
    left unmachined; each region's own report too."""
    reports = []
    real = steep_shallow.uncut_report
    monkeypatch.setattr(steep_shallow, "uncut_report",
                        lambda *a: reports.append(real(*a)) or reports[-1])
    prog = cadcnc.finish(part(name), faces, radius=radius, scallop=scallop,
                         strategy="steep-shallow", threshold=45.0, overlap=0.5)
    assert len(reports) == 2
    for r in reports:
        assert r.limit == scallop
        assert 0.0 < r.max_scallop <= scallop + 1e-6   # the report's own tolerance
        assert r.over_limit_area == 0.0
        assert r.unmachined_area == 0.0
    note = next(n for n in prog.notes if n.startswith("uncut"))
    assert "0.00 mm^2 over the limit" in note


def test_an_oblique_edge_is_served_by_the_next_plane_or_the_leaving_pass_end():
    """The boss's fillet foot (a circle r 11 on the plate) runs at every angle to the
    planes (angle 0): at each of its samples where the centre coordinate changes slower
    than 0.9 g mm per mm, either a plane lies within half a chord on the face's side, or
    the plane on the outer side at f - x ends its pass x / (s g) along the edge, within
    half a chord (c / g, c the spacing)."""
    fillet = FACTS["boss"]["fillet"]
    faces = FACTS["boss"]["faces"]
    s = sample_faces(part("boss"), faces, float(centre_chord(0.05, 0.0, 2.0)) / 4)
    plan = plan_planes(s, 2.0, 0.0, 0.0, scallop=0.05)
    k, g = across(s, plan.normal)
    side, slope = along_edges(s, plan.f, g)
    foot = (s.faces == fillet) & s.edge & (np.abs(s.points[:, 2] - 5.0) < 1e-6)
    oblique = foot & (side != 0) & (slope > 0.3) & (slope < 0.9)   # not along the planes
    assert oblique.sum() > 50
    planes = np.sort(plan.offsets)
    for i in np.flatnonzero(foot & (side != 0) & (plan.reason == "")):
        x = (planes - plan.f[i]) * side[i]                 # > 0: on the face's side
        inside, outside = x[x >= 0], -x[x <= 0]
        half = 0.5 * plan.spacing[i]
        assert (len(inside) and inside.min() <= half + 1e-9) or (
            len(outside) and outside.min() / slope[i] <= half + 1e-9), i
