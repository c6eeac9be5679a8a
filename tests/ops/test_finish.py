"""Finishing: plane spacing against closed forms, every cut on its offset, nothing gouged,
links verified, what was left uncut, faces given the CadQuery way, bad input refused."""

from __future__ import annotations

import math

import numpy as np
import pytest

import cadcnc
from cadcnc.guard.moves import MoveClearance
from cadcnc.ops.finish.plan import centre_chord, plan_planes, sample_faces
from cadcnc.ops.finish.raster import plan_for_job
from cadcnc.ops.finish.shortcut import finish
from cadcnc.ops.finish.uncut import measured_rows, uncut_report, uncut_tasks
from cadcnc.verification import gate_program
from cadcnc.verification.probe import shape_distances
from helpers.fixtures import FIXTURES

pytestmark = pytest.mark.slow  # over about 5 s a test (pyproject.toml)

R = 3.0
_runs: dict = {}


def run(name: str, faces, **kw):
    """(part, program) of a finishing fixture, computed once per session."""
    kw.setdefault("stepover", 2.0)
    key = (name, tuple(faces), tuple(sorted(kw.items())))
    if key not in _runs:
        part = cadcnc.load_step(FIXTURES / f"finish_{name}.step")
        calls = []
        prog = finish(part, faces, radius=R, progress=lambda *a: calls.append(a), **kw)
        _runs[key] = (part, prog, calls)
    return _runs[key]


def flat(h: float) -> float:
    return 2.0 * math.sqrt(2.0 * R * h - h * h)


def cq_part(wp):
    return cadcnc.Part.from_cadquery(wp), wp


# -- spacing against closed forms ----------------------------------------------------------
def test_flat_floor_planes_are_the_flat_chord_apart():
    import cadquery as cq

    part, wp = cq_part(cq.Workplane("XY").box(40, 30, 10))
    top = part.face_number(wp.faces(">Z").val())
    plan = plan_planes(sample_faces(part, [top], 0.25), R, 0.0, 0.0, scallop=0.01)
    np.testing.assert_allclose(np.diff(plan.offsets)[:-1], flat(0.01), rtol=1e-12)
    assert np.diff(plan.offsets)[-1] <= flat(0.01) * (1 + 1e-12)
    # the centres cover y -15..15: the first and last plane within half a spacing of it,
    # inside the face (a plane beyond the edge has no pass: the edge is cut from inside)
    assert -15 < plan.offsets[0] <= -15 + flat(0.01) / 2 + 1e-9
    assert 15 - flat(0.01) / 2 - 1e-9 <= plan.offsets[-1] < 15


@pytest.mark.parametrize("slope_deg", [20.0, 50.0])
def test_sloped_plane_spacing_is_the_chord_times_cosine(slope_deg):
    """A top sloping across the passes by phi: the planes are 2 sqrt(2RH - H^2) cos phi
    apart (the spacing on the surface is the flat one)."""
    import cadquery as cq

    t = math.tan(math.radians(slope_deg))
    wp = cq.Workplane("YZ").polyline([(0, 0), (20, 0), (20, 5 + 20 * t), (0, 5)]).close() \
        .extrude(30)
    part = cadcnc.Part.from_cadquery(wp)
    top = [n for n in range(1, len(part) + 1)
           if abs(part.face(n).normal(*np.mean([part.face(n).u_range, part.face(n).w_range],
                                                axis=1))[1] + math.sin(math.radians(
                                                    slope_deg))) < 1e-9]
    assert len(top) == 1
    plan = plan_planes(sample_faces(part, top, 0.25), R, 0.0, 0.0, scallop=0.02)
    np.testing.assert_allclose(np.diff(plan.offsets),
                               flat(0.02) * math.cos(math.radians(slope_deg)), rtol=1e-9)


def _cusp_on_circle(theta1, theta2, rho, radius):
    """Exact cusp height between two balls R on a convex circle rho at angles theta."""
    big = rho + radius
    a = abs(theta2 - theta1) / 2
    r_q = big * math.cos(a) - math.sqrt(radius ** 2 - (big * math.sin(a)) ** 2)
    return r_q - rho


def test_cylinder_across_the_passes_keeps_the_scallop_exactly():
    """A cylinder r 10 along the passes: centres on the circle r 13; between every two
    planes over the reachable top the exact cusp stays <= H, and the plan does not waste
    passes (the tightest pair is within 10 % of H)."""
    import cadquery as cq

    part = cadcnc.Part.from_cadquery(cq.Workplane("YZ").circle(10).extrude(40))
    lateral = [n for n in range(1, len(part) + 1) if part.face(n).kind == "cylinder"]
    H = 0.01
    plan = plan_planes(sample_faces(part, lateral, 0.1), R, 0.0, 0.0, scallop=H)
    th = np.arcsin(np.clip(plan.offsets / 13.0, -1, 1))
    cusps = [_cusp_on_circle(a, b, 10.0, R) for a, b in zip(th, th[1:])
             if max(abs(a), abs(b)) < math.radians(80)]
    assert len(cusps) > 20
    assert max(cusps) <= H * (1 + 1e-9)
    assert max(cusps) >= 0.9 * H
    assert (plan.reason == "unreachable").sum() > 0.45 * len(plan.reason)


@pytest.mark.parametrize("k", [-0.2, -0.05, 0.05, 0.2])
def test_centre_chord_is_the_circle_closed_form(k):
    """Two balls R on a circle of curvature k (convex < 0), centres c apart: their cusp
    is H above the surface (law of cosines, independently of the formula's algebra)."""
    H = 0.02
    c = float(centre_chord(H, k, R))
    rho = -1.0 / k
    big = abs(rho + R)                      # the centres' circle
    a = math.asin(c / (2 * big))
    # cusp on the bisector, R from a centre: |Q| from the circle's centre
    s = math.sqrt(R ** 2 - (big * math.sin(a)) ** 2)
    q = big * math.cos(a) + (-s if rho > 0 else s)
    assert abs(q) - abs(rho) == pytest.approx(H if rho > 0 else -H, abs=1e-12)


# -- the program on the fixtures -----------------------------------------------------------
# stepover 4 on the slab, the boss and the hole (2 on the fillet): the offset and the gate
# are judged point by point and move by move, whatever the spacing of the planes; at 4 the
# hole still splits two of its eight planes into two cuts each, the boss's passes still
# meet the boss (collision and unreachable records), and the OCCT distance (2 ms a point)
# has half as many points to measure.
@pytest.mark.parametrize("name,faces,stepover", [("slab", [5], 4.0), ("boss", [6], 4.0),
                                                 ("hole", [5], 4.0), ("fillet", [6, 3], 2.0)])
def test_every_cut_point_on_the_offset_and_nothing_gouges(name, faces, stepover):
    part, prog, calls = run(name, faces, stepover=stepover)
    assert prog.cuts and prog.complete
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    comp = TopoDS_Compound()
    b = BRep_Builder()
    b.MakeCompound(comp)
    for n in faces:
        b.Add(comp, part.face(n).topods)
    pts = np.vstack([c.points for c in prog.cuts])
    dev = shape_distances(comp, pts) - R
    assert np.abs(dev).max() <= 1e-6, np.abs(dev).max()
    gate = gate_program(prog, part)
    assert gate.ok, gate.message
    # one report as each plane ends (1..N of N), plus heartbeats within a slow plane (a
    # cold kernel cache), which repeat the planes done so far
    done, totals = [c[0] for c in calls], {c[1] for c in calls}
    assert len(totals) == 1 and done == sorted(done)
    n = totals.pop()
    assert sorted(set(done) - {0}) == list(range(1, n + 1)) and done[-1] == n


def test_zigzag_stays_down_only_where_verified_and_oneway_retracts():
    part, zig, _ = run("fillet", [6, 3])
    _, one, _ = run("fillet", [6, 3], pattern="oneway")
    moves = MoveClearance(part, R, zig.job.tool.shank)
    down = [s for s in zig.links if len(s.points) == 2 and not s.rapid.any()
            and np.linalg.norm(s.points[1] - s.points[0]) > 1e-6]
    assert down, "the fillet's passes end on open edges: some links stay down"
    for s in down:
        assert moves.distance(*s.points) >= R - 1e-6
    between = one.links[1:-1]
    assert all(s.rapid.any() or s.length <= 1e-6 for s in between)
    assert one.cut_length == pytest.approx(zig.cut_length, rel=1e-6)
    d = [c.points[-1, 0] - c.points[0, 0] for c in one.cuts if len(c.points) > 10]
    assert all(v > 0 for v in d)  # one way: every pass along +X


def test_boss_is_left_where_the_ball_cannot_reach():
    """The free-form top around a boss r 4 (axis (5, 2)): the ball touching the top cannot
    come nearer than R to the boss, so a ring about it is left, at most the ring r 4..7 in
    plan (103.7 mm^2 on the flat; the top slopes a little)."""
    part, prog, _ = run("boss", [6])
    plan, samples = plan_for_job(part, prog.job)
    rep = uncut_report(prog, part, samples, plan)
    assert set(rep.by_reason()) == {"collision"}
    assert 20.0 < rep.unmachined_area < math.pi * (7 ** 2 - 4 ** 2) * 1.1
    assert any(s.reason == "unreachable" and "in the way" in s.detail for s in prog.skipped)
    assert any(s.reason == "collision" for s in prog.skipped)  # the passes' own records


def test_the_uncut_report_does_not_depend_on_blocks_or_processes():
    """The samples measured in one block here, in three blocks here, and in two blocks on
    two worker processes: the same leftovers, scallops and report."""
    part, prog, _ = run("boss", [6])
    plan, samples = plan_for_job(part, prog.job)
    points = [c.points for c in prog.cuts]
    rows = [measured_rows(None, t) for t in uncut_tasks(points, prog.job, samples, plan, 1)]
    three = [measured_rows(None, t) for t in uncut_tasks(points, prog.job, samples, plan, 3)]
    assert len(rows) == 1 and len(three) == 3
    for one, split in zip(rows[0], (np.concatenate(x) for x in zip(*three))):
        assert np.array_equal(one, split, equal_nan=True)
    here, there = uncut_report(prog, part, samples, plan), uncut_report(prog, part, samples,
                                                                        plan, jobs=2)
    assert here == there and here.notes() == there.notes() and here.unmachined


def test_cylinder_lower_half_is_unreachable_and_scallop_reported():
    import cadquery as cq

    wp = cq.Workplane("YZ").circle(10).extrude(40)
    prog = finish(wp, wp.faces("%CYLINDER"), radius=R, scallop=0.05)
    part = cadcnc.Part.from_cadquery(wp)
    plan, samples = plan_for_job(part, prog.job)
    rep = uncut_report(prog, part, samples, plan)
    half = math.pi * 10 * 40
    assert rep.by_reason()["unreachable"] == pytest.approx(half, rel=0.02)
    assert rep.max_scallop <= 0.05 * 1.02
    assert any("largest scallop" in n for n in prog.notes)


# -- inputs --------------------------------------------------------------------------------
def test_faces_as_numbers_cadquery_faces_or_a_selection():
    import cadquery as cq

    wp = cq.Workplane("XY").box(20, 10, 5)
    part = cadcnc.Part.from_cadquery(wp)
    n = part.face_number(wp.faces(">Z").val())
    progs = [finish(part, [n], radius=2.0, stepover=2.0),
             finish(wp, wp.faces(">Z"), radius=2.0, stepover=2.0),
             finish(wp, wp.faces(">Z").val(), radius=2.0, stepover=2.0)]
    for p in progs[1:]:
        assert len(p.cuts) == len(progs[0].cuts)
        for a, b in zip(p.cuts, progs[0].cuts):
            np.testing.assert_array_equal(a.points, b.points)
    other = cq.Workplane("XY").box(20, 10, 5)
    with pytest.raises(cadcnc.InputError, match="not a face of the part"):
        finish(wp, other.faces(">Z"), radius=2.0, stepover=2.0)


@pytest.mark.parametrize("kw,match", [
    (dict(faces=[99], stepover=1.0), "out of range"),
    (dict(faces=[5], stepover=1.0, scallop=0.01), "exactly one"),
    (dict(faces=[5]), "exactly one"),
    (dict(faces=[5], stepover=-1.0), "stepover"),
    (dict(faces=[5], scallop=0.0), "scallop"),
    (dict(faces=[5], stepover=1.0, pattern="spiral"), "pattern"),
    (dict(faces=[5], stepover=1.0, angle=float("nan")), "angle"),
    (dict(faces=[5], stepover=1.0, allowance=-1.0), "allowance"),
    (dict(faces=[], stepover=1.0), "no face"),
])
def test_bad_input_is_refused_clearly(kw, match):
    part = cadcnc.load_step(FIXTURES / "finish_slab.step")
    faces = kw.pop("faces")
    with pytest.raises(cadcnc.CadcncError, match=match):
        finish(part, faces, radius=R, **kw)


def test_a_face_pointing_down_is_refused():
    import cadquery as cq

    wp = cq.Workplane("XY").box(20, 10, 5)
    with pytest.raises(cadcnc.InputError, match="points down"):
        finish(wp, wp.faces("<Z"), radius=2.0, stepover=2.0)
