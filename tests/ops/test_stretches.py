"""Every feasible stretch of a corner, against the closed forms of the stretch fixtures.

The sidecar (fixtures/stretch_fixtures.json, written by build_stretch_fixtures.py from
the fixtures' construction) gives each stretch's limits as nominal ball centres; the
spec's 1 µm tolerances (a third face nearer than R' - 1 µm, a contact 1 µm off its face)
move each limit outward by ``outward_per_um`` µm along the curve. A limit is located to
``Tolerances.stretch_limit`` (LIMIT below), always on the feasible side. The straight corners
run along +x, so a limit's place along the curve is its x; the boss's base edge is a
closed curve with its own test.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import EXIT_NOTHING, NothingToCutError
from cadcnc.core.job import Tool
from cadcnc.core.tolerances import DEFAULT
from cadcnc.guard import guard_for
from cadcnc.ops.path.feasibility import COLLISION, REASONS, Feasibility
from cadcnc.ops.path.stretch_paths import nearest_start, stretch_paths
from cadcnc.ops.path.stretches import pair_stretches
from helpers.fixtures import FIXTURES, stretch_pair_job

SIDECAR = json.loads((FIXTURES / "stretch_fixtures.json").read_text())
UM = 1e-6
LIMIT = DEFAULT.stretch_limit   # mm: a limit's accuracy, on the feasible side
_cache: dict = {}


def setup(name):
    """(s1, s2, job, per-edge stretches) of a fixture's pair, computed once."""
    if name not in _cache:
        s1, s2, job = stretch_pair_job(name)
        _cache[name] = (s1, s2, job, pair_stretches(s1, s2, job))
    return _cache[name]


def check_limit(limit, expected, outward: float):
    """A located limit against its closed form: place along +x on the feasible side of
    it (inward, against ``outward``) by at most LIMIT (round-off 1e-9), off-curve
    coordinates to 1 µm, its rule, and the face (and ball/shank) it names."""
    x, y, z = expected["p"]
    x_tol = x + outward * expected["outward_per_um"] * UM
    inward = (x_tol - limit.p[0]) * outward
    assert -1e-9 <= inward <= LIMIT, (limit, expected)
    assert limit.p[1:] == pytest.approx((y, z), abs=UM)
    assert limit.rule == expected["rule"], limit.detail
    if expected["faces"]:
        named = [int(w.split()[0]) for w in limit.detail.split("face ")[1:]]
        assert named and set(named) <= set(expected["faces"]), limit.detail
    if "who" in expected:
        assert limit.detail.startswith(expected["who"] + " touches"), limit.detail


@pytest.mark.parametrize("name", [n for n in SIDECAR if SIDECAR[n]["stretches"]
                                  and n != "boss"])
def test_stretch_limits_match_closed_forms(name):
    *_, found = setup(name)
    (edge,) = found
    assert edge.missed == 0
    assert len(edge.stretches) == len(SIDECAR[name]["stretches"])
    for got, want in zip(edge.stretches, SIDECAR[name]["stretches"]):
        check_limit(got.start, want["start"], -1.0)
        check_limit(got.end, want["end"], +1.0)
        # the length follows the limits (straight corner)
        assert got.length == pytest.approx(got.end.p[0] - got.start.p[0], abs=UM)
        assert got.direction[0] > 0.0


def test_closed_edge_boss_on_curved_floor_has_two_mirror_stretches():
    """The boss contact leaves the boss over its top circle: at each limit it is within
    the 1 µm boundary tolerance above the circle, and the centre is the closed form for
    that contact height (on r = boss_r + R' about z, R' from the floor cylinder)."""
    facts = SIDECAR["boss"]
    s1, s2, job, found = setup("boss")
    (edge,) = found
    assert edge.missed == 0 and len(edge.stretches) == 2
    expected = [np.array(lim["p"]) for st in facts["stretches"]
                for lim in (st["start"], st["end"])]
    got = [lim for st in edge.stretches for lim in (st.start, st.end)]
    r, top, rb, rf = facts["radius"], facts["top"], facts["boss_r"], facts["floor_r"]
    for lim in got:
        assert lim.rule == "boundary" and lim.detail == f"contact off face {s2.number}"
        q = s2.point(*lim.tangency.uv2)
        assert np.hypot(q[0], q[1]) == pytest.approx(rb, abs=1e-9)
        delta = q[2] - top
        assert -LIMIT <= delta <= UM   # on the face, to the limit's accuracy
        y = np.sqrt((rf + r) ** 2 - (top + delta + rf) ** 2)
        x = np.sqrt((rb + r) ** 2 - y * y)
        assert np.abs(np.abs(lim.p) - (x, y, top + delta)).max() < 1e-8
        nearest = min(expected, key=lambda e: np.linalg.norm(e - lim.p))
        assert np.linalg.norm(nearest - lim.p) < 20 * UM + LIMIT   # mirror images
        expected = [e for e in expected if e is not nearest]
    lengths = [st.length for st in edge.stretches]
    assert lengths[0] == pytest.approx(lengths[1], abs=2 * LIMIT)


@pytest.mark.parametrize("name", [n for n in SIDECAR if "refusal" in SIDECAR[n]])
def test_edge_without_stretch_is_refused_with_its_reason(name):
    s1, s2, job, found = setup(name)
    want = SIDECAR[name]["refusal"]
    (edge,) = found
    assert edge.stretches == [] and edge.missed == 0
    msg = edge.refusal
    assert REASONS[COLLISION] in msg
    assert f"{want['who']} touches face {want['faces'][0]}" in msg
    # the depth named is the closed form's (R' - 1 µm is the threshold)
    too_near = -(want["margin"] + UM)
    assert f"({too_near:.4g} mm too near)" in msg
    with pytest.raises(NothingToCutError, match=f"faces {s1.number} and {s2.number}: no "
                       "feasible") as err:   # a valid pair with nothing to cut: exit 3
        stretch_paths(s1, s2, job, found=found)
    assert err.value.exit_code == EXIT_NOTHING


def test_a_path_per_stretch_runs_between_its_limits():
    s1, s2, job, found = setup("shelf")
    paths = stretch_paths(s1, s2, job, found=found)
    assert len(paths) == 2
    for stretch, path in paths:
        assert path.stop_reason == "end"
        assert np.allclose(path.points[0], stretch.start.p, atol=1e-9)
        assert np.allclose(path.points[-1], stretch.end.p, atol=1e-9)
        # the corner is straight: every centre on the line y = 8, z = 11
        assert np.abs(path.points[:, 1:] - (8.0, 11.0)).max() < UM


def test_user_start_outside_the_stretch_moves_to_the_nearest_limit():
    s1, s2, job, found = setup("shelf")
    feas = Feasibility(s1, s2, job, guard_for(s1.part, (s1.number, s2.number), job))
    inside, note = nearest_start(found, feas, (12.0, 8.0, 11.0))
    assert note == "" and inside.p == pytest.approx((12.0, 8.0, 11.0), abs=1e-9)
    # under the shelf (x 22..38 is blocked): from x = 31 the nearest limit is x = 38
    moved, note = nearest_start(found, feas, (31.0, 8.0, 11.0))
    assert 38.0 - UM - 1e-9 <= moved.p[0] <= 38.0 - UM + LIMIT   # the feasible side
    assert "moved to the nearest stretch limit" in note and "collision" in note
    moved, _ = nearest_start(found, feas, (24.0, 8.0, 11.0))
    assert 22.0 + UM - LIMIT <= moved.p[0] <= 22.0 + UM + 1e-9


class _Circle:
    """A closed edge stub: a circle of circumference 10 mm, walked by arc length."""

    closed, length = True, 10.0

    def point_tangent(self, s):
        a = 2 * np.pi * (s % self.length) / self.length
        r = self.length / (2 * np.pi)
        return np.array([r * np.cos(a), r * np.sin(a), 0.0]), np.array([-np.sin(a),
                                                                           np.cos(a), 0.0])


class _Window:
    """Feasible for arc length (mod 10) in [9.9, 10) and [0, 2.5]: a window across the
    seam whose start lies between the last sample (9.8) and the first (0); the ball
    centre is the anchor itself."""

    def exact(self, x):
        return x   # no clearance rule: every verdict is already exact

    def sample(self, s, anchor, tangent, seed=None, quick=False):
        from cadcnc.interp.stepper import Tangency
        from cadcnc.ops.path.feasibility import BOUNDARY, FEASIBLE, Sample

        u = s % 10.0
        ok = u >= 9.9 or u <= 2.5
        tan = Tangency(tuple(map(float, anchor)), (0.0, 0.0), (0.0, 0.0))
        return Sample(s, FEASIBLE if ok else BOUNDARY, "" if ok else "off", tan,
                      tuple(map(float, tangent)))


def test_a_stretch_across_the_seam_of_a_closed_edge_is_one_stretch():
    from cadcnc.ops.path.stretches import EdgeStretches, _refine, _stretches

    curve, feas = _Circle(), _Window()
    grid = np.arange(0.0, 10.0, 0.2)
    samples = [feas.sample(s, *curve.point_tangent(s)) for s in grid]
    samples = _refine(feas, curve, samples, EdgeStretches(0, curve.length))
    (st,) = _stretches(feas, curve, samples, 0)
    assert st.start.s % 10.0 == pytest.approx(9.9, abs=1e-6)
    assert st.end.s % 10.0 == pytest.approx(2.5, abs=1e-6)
    assert st.start.rule == st.end.rule == "boundary"
    # 2.6 mm of arc on a circle of radius 10 / 2 pi (not 7.4 mm the other way round):
    # the polyline of 0.2 mm chords is shorter by about 13 x 0.2^3 / (24 r^2) = 2e-3 mm
    assert 2.6 - 3e-3 < st.length <= 2.6


def test_a_hole_of_the_balls_radius_is_one_position_cut_as_a_point():
    """narrow_slot's flat-bottom hole r 2 at (10, 10), floor z 15, with a ball R' = 2:
    the ball fits the hole exactly (R' k = 1, a tie, not a gouge: every point of the wall
    and floor is R' from the centre), so the whole bottom edge is one feasible position,
    the closed form (10, 10, 17), and its program is a single-point cut."""
    from cadcnc.core.job import Job, PairPath
    from cadcnc.ops.path.pair_program import program_for_job

    part = cadcnc.load_step(FIXTURES / "narrow_slot.step")
    job = Job(Tool(2.0), 1500.0, 0.004, PairPath(faces=(11, 12), edge=None))
    (edge,) = pair_stretches(part.face(11), part.face(12), job)
    (st,) = edge.stretches
    assert st.length < 1e-6 and st.start.p == pytest.approx((10.0, 10.0, 17.0), abs=UM)
    assert all(x.ok for x in edge.samples)
    (cut,) = program_for_job(part, job).cuts
    assert cut.points.shape == (1, 3) and cut.complete
    np.testing.assert_allclose(cut.points[0], (10.0, 10.0, 17.0), atol=UM)
    # a ball 2 um larger than the hole would cut its wall by ~4 um > 1 um: refused
    feas = Feasibility(part.face(11), part.face(12),
                       replace(job, tool=Tool(2.0 + 2e-3)), None)
    assert feas.judge(st.start.tangency)[0] == "curvature"
