"""The surface bound that stands in for OCCT's global search on the gate's sampled cycles
(cadcnc/verification/surface_bound.py, issue 37 item 6).

Sound: it never proves a floor above OCCT's global distance (random points about three
B-spline faces); it refuses a foot that is not the nearest point; and the bounded check
gives the same answers with it as without it, on a finishing cut of the wave slab with
its own seeds and with wrong ones (where it must fall back to OCCT and report the
disagreements).
"""

from __future__ import annotations

import json
from functools import cache

import numpy as np
import pytest

import cadcnc
from cadcnc.core.job import Job, PairPath, Tool
from cadcnc.ops.finish.passes import GuidePlane, pass_cuts
from cadcnc.verification.probe import FaceProbe
from cadcnc.verification.surface_bound import SurfaceBound, min_distance_bound
from cadcnc.verification.surface_checks import check_surface
from helpers.fixtures import FIXTURES

WAVE = json.loads((FIXTURES / "finish_fixtures.json").read_text())["wave"]
ROUND = 1e-9  # mm: OCCT's distances to their last digits


@cache
def wave_part():
    return cadcnc.load_step(FIXTURES / WAVE["file"])


def _near_points(probe: FaceProbe, count: int, seed: int) -> list[np.ndarray]:
    """Points 0.3-4 mm from random points of the face's surface, mostly on its outer
    side (a ball centre's), some inside."""
    u0, u1, w0, w1 = probe.box
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        n = probe.normal(rng.uniform(u0, u1), rng.uniform(w0, w1))
        side = 1.0 if rng.random() < 0.8 else -1.0
        out.append(np.array(probe._p.Coord()) + side * rng.uniform(0.3, 4.0) * n)
    return out


@pytest.mark.parametrize("name, face", [("wave", None), ("finish_slab.step", 5),
                                        ("bspline_boss.step", 4)])
def test_the_bound_never_exceeds_occts_global_distance(name, face):
    part = wave_part() if name == "wave" else cadcnc.load_step(FIXTURES / name)
    probe = FaceProbe(part.face(face or WAVE["top"]).topods)
    bound = SurfaceBound.of(probe.adaptor, probe.surface)
    assert bound is not None
    proven = 0
    for p in _near_points(probe, 40, 7):
        u, w, d = probe.project_global(p)
        floor = min_distance_bound(bound, probe.adaptor, p, u, w, 0.0, 2.0 * d)
        assert floor <= d + ROUND
        proven += floor >= d - 1e-6   # mm: proven to within a micron
    if name == "wave":   # the slab of the gate's pace: every point proven
        assert proven == 40


def test_a_foot_that_is_not_nearest_is_not_proven():
    """From a point above the wave, a foot on a far crest is farther than the nearest
    point: the bound must not prove its distance (nor anything above the true one)."""
    probe = FaceProbe(wave_part().face(WAVE["top"]).topods)
    bound = SurfaceBound.of(probe.adaptor, probe.surface)
    p = np.array([0.0, 0.0, 14.0])
    u, w, d = probe.project_global(p)
    far = np.array(probe.surface.Value(20.0, 10.0).Coord())
    assert not bound.clear(probe.adaptor, p, 20.0, 10.0, float(np.linalg.norm(far - p)))
    assert bound.clear(probe.adaptor, p, u, w, d - 1e-8)   # mm: the noise below the foot
    assert not bound.clear(probe.adaptor, p, u, w, d + 1e-6)   # mm: above it


@cache
def wave_cut():
    """One finishing pass across the wave slab (the plane y = 5), its first cut."""
    job = Job(Tool(3.0), 1500.0, 0.004, PairPath())
    return pass_cuts(wave_part(), [WAVE["top"]], GuidePlane(0.0, 5.0), job).cuts[0].path


def _misled(probe: FaceProbe) -> None:
    """Make the probe's seeded search answer with a foot 12 mm along u of the right one
    (what seeds that steer OCCT's local search to another critical point would give)."""
    right = probe.project_seeded

    def wrong(point, u0, w0):
        u, w, _ = right(point, u0, w0)
        u = u + 12.0 if u + 12.0 < probe.box[1] else u - 12.0
        return u, w, float(np.linalg.norm(np.array(probe.surface.Value(u, w).Coord())
                                          - np.asarray(point)))
    probe.project_seeded = wrong


@pytest.mark.parametrize("wrong", [False, True])
def test_the_bounded_check_answers_as_without_the_bound(wrong, monkeypatch):
    tp = wave_cut()
    tol = wave_part().tol

    def check():
        probe = FaceProbe(wave_part().face(WAVE["top"]).topods, tol)
        if wrong:
            _misled(probe)
        return check_surface(probe, WAVE["top"], 3.0, tp.points, tp.uv[:, 0], 64, tol,
                             bounded=True)

    with_bound = check()
    monkeypatch.setattr(FaceProbe, "surface_clear", lambda self, *a: False)
    without = check()
    for field in ("deviation", "face_deviation"):
        np.testing.assert_array_equal(getattr(with_bound, field), getattr(without, field))
    assert with_bound.states == without.states
    assert (with_bound.unseeded_disagreements, with_bound.unseeded_max_gain_mm) == \
        (without.unseeded_disagreements, without.unseeded_max_gain_mm)
    assert (with_bound.unseeded_disagreements > 0) == wrong


@pytest.mark.parametrize("name, face", [("wave", None), ("finish_slab.step", 5),
                                        ("bspline_boss.step", 4)])
def test_the_patch_boxes_floor_never_exceeds_occts_distance(name, face):
    """``SurfaceBound.floor`` (the nearest Bezier patch's box) is a lower bound of the
    distance to the face, which OCCT measures (DistShapeShape), near the face and up to
    20 mm above it; well above the face it is within a patch's height of it."""
    part = wave_part() if name == "wave" else cadcnc.load_step(FIXTURES / name)
    probe = FaceProbe(part.face(face or WAVE["top"]).topods)
    points = _near_points(probe, 30, 11)
    rng = np.random.default_rng(3)
    u0, u1, w0, w1 = probe.box
    for _ in range(30):   # higher along the normal, as a link's points are
        n = probe.normal(rng.uniform(u0, u1), rng.uniform(w0, w1))
        points.append(np.array(probe._p.Coord()) + rng.uniform(4.0, 20.0) * n)
    floor = probe.surface_floor(np.array(points))
    exact = np.array([probe.face_distance(p)[1] for p in points])
    assert (floor <= exact + ROUND).all(), (floor - exact).max()
    if name == "wave":   # 2 mm patches of a gentle wave: the boxes are tight
        assert (exact[30:] - floor[30:]).max() < 1.0


def _wave_program():
    """(part, program, G-code keywords): the wave's finish at stepover 10, as written."""
    from cadcnc.io.gcode import blend_for
    from cadcnc.ops.finish.shortcut import finish

    part = wave_part()
    program = finish(part, [WAVE["top"]], radius=3.0, stepover=10.0)
    return part, program, dict(tolerance=None, tool_tip=False,
                               blend=blend_for(program.job.tolerances.gouge))


def _gated(part, program, gcode) -> tuple[list, list, int]:
    """(verdicts, depths, point-to-face distances) of the program gated as written; every
    move's proven depth bound within the allowance."""
    from cadcnc.verification.written_gate import gate_written

    gate = gate_written(program, part, gcode)
    assert all(r.sweep.depth_bound_mm <= r.sweep.allowance_mm for r in gate.results)
    return ([r.ok for r in gate.results], [r.depth_mm for r in gate.results],
            sum(r.sweep.distances_evaluated for r in gate.results))


def _same_verdicts_no_deeper_fewer(now, without) -> None:
    assert now[0] == without[0] and all(now[0])
    assert all(a <= b + 1e-12 for a, b in zip(now[1], without[1]))
    assert now[2] < without[2]


def test_moves_proven_by_their_bounds_need_fewer_distances_and_keep_the_verdict(
        monkeypatch):
    """The wave's finish (stepover 10) gated as written: with the patch boxes' floor and
    moves proven by their ends' bounds, one end near the face and the other far
    (``Polyline._proven``), the verdicts are those of the gate without them, with fewer
    point-to-face distances. A cut's depth is the deepest measured (a lower bound of the
    true deepest): with fewer measurements it is no deeper; the proven bound of every
    move's depth stays within the allowance."""
    from cadcnc.verification import sweep

    part, program, gcode = _wave_program()
    now = _gated(part, program, gcode)
    monkeypatch.setattr(sweep.Polyline, "_proven",
                        lambda self, k, lb, near_seg, need: (near_seg, need, None))
    _same_verdicts_no_deeper_fewer(now, _gated(part, program, gcode))


def test_the_previous_cuts_last_centre_floors_the_next_cuts_moves(monkeypatch):
    """``before_floors``: at every move of the wave's program (stepover 10) gated as
    written, the floor from the previous cut's last centre is at most the distance OCCT
    measures (DistShapeShape) to that face; gated with it, the verdicts are those without
    it, depths no deeper (the deepest measured) and fewer point-to-face distances."""
    from cadcnc.io.program_gcode import program_written_moves
    from cadcnc.verification import program_gate
    from cadcnc.verification.gate_cache import cache_for
    from cadcnc.verification.program_gate import cut_moves, last_centre
    from cadcnc.verification.whole_part import before_floors

    part, program, gcode = _wave_program()
    tol = program.job.tolerances
    faces = cache_for(part, tol).faces
    per_cut = cut_moves(program, program_written_moves(program, **gcode))
    checked = 0
    for prev, (moves, _) in zip(program.cuts[:-1], per_cut[1:]):
        floors = before_floors(faces, last_centre(prev.path), moves, tol)
        assert set(floors) == {WAVE["top"]}   # proven at every pass end of this wave
        floor, probe = floors[WAVE["top"]], faces.probe(WAVE["top"])
        for j in np.nonzero(floor > 0.0)[0]:
            assert floor[j] <= probe.face_distance(moves[j])[1] + ROUND
            checked += 1
    assert checked > 0
    now = _gated(part, program, gcode)
    monkeypatch.setattr(program_gate, "last_centre", lambda path: None)
    _same_verdicts_no_deeper_fewer(now, _gated(part, program, gcode))
