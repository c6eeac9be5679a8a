"""The gate's faster roads to OCCT's distances (issue 24) give OCCT's distances.

- Faces that are planes in all but name (the extruded sides of finish_slab and
  bspline_boss) get a twin on a true plane: its closed form equals DistShapeShape's
  distance to the face, signed and unsigned, within 1e-9 mm; curved faces get none.
- An interior foot proven nearest (OCCT's global search, or the radial foot on a
  cylinder, sphere or torus, and OCCT's edge projections:
  :meth:`FaceProbe.interior_distance`) is DistShapeShape's distance within 1e-9 mm.
- Moves are matched to the same centres as the windowed rule did (k-d tree shortcut).
- A finishing program on finish_slab (extruded sides, B-spline top), clean and seeded
  with a gouge: the same verdicts and depths as the reference gate.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from OCP.GeomAbs import (
    GeomAbs_BSplineSurface,
    GeomAbs_Cylinder,
    GeomAbs_Sphere,
    GeomAbs_SurfaceOfExtrusion,
    GeomAbs_Torus,
)

import cadcnc
from cadcnc.core.job import Job, Raster, Tool
from cadcnc.program.program import CutSegment, Program
from cadcnc.verification import gate_program
from cadcnc.verification.gate_cache import shared_gates
from cadcnc.verification.planar import planar_twin
from cadcnc.verification.probe import FaceProbe
from cadcnc.verification.whole_part import _match, window_match
from helpers.fixtures import FIXTURES
from helpers.gate_results import DEPTH, same


def _load(name: str):
    return cadcnc.load_step(FIXTURES / f"{name}.step")


def _around(probe: FaceProbe, n: int, seed: int) -> np.ndarray:
    lo, hi = probe.bbox()
    return np.random.default_rng(seed).uniform(lo - 3, hi + 3, (n, 3))


def _agreeing(probe: FaceProbe, fast, n: int, seed: int) -> int:
    """How many of ``n`` points around the face ``fast`` answers; each answer must be
    DistShapeShape's (signed, unsigned) within 1e-9 mm."""
    answered = 0
    for p in _around(probe, n, seed):
        found = fast(p)
        if found is not None:
            answered += 1
            np.testing.assert_allclose(found, probe.face_distance(p), atol=DEPTH)
    return answered


@pytest.mark.parametrize("name", ["finish_slab", "bspline_boss"])
def test_planar_twins_give_occts_distances(name):
    """Four extruded sides each; the B-spline tops, a cylinder, a true plane: no twin."""
    part = _load(name)
    compared = twins = 0
    for k in range(1, len(part) + 1):
        probe = FaceProbe(part.face(k).topods, part.tol)
        twin = planar_twin(probe, part.tol)
        assert (twin is not None) == (probe.adaptor.GetType() == GeomAbs_SurfaceOfExtrusion)
        twins += twin is not None
        if twin is None:
            continue
        compared += _agreeing(probe, twin.plane_distance, 25, k)
    assert twins == 4 and compared > 60


@pytest.mark.parametrize("name, kinds", [
    ("bspline_boss", {GeomAbs_BSplineSurface}),        # OCCT's global search
    ("sphere_cylinder", {GeomAbs_Sphere, GeomAbs_Cylinder}),   # radial feet
    ("fillet_pocket", {GeomAbs_Torus}),
])
def test_interior_feet_give_occts_distances(name, kinds):
    part = _load(name)
    found = 0
    for k in range(1, len(part) + 1):
        probe = FaceProbe(part.face(k).topods, part.tol)
        if probe.adaptor.GetType() not in kinds:
            continue
        found += _agreeing(probe, probe.interior_distance, 30, k)
    assert found > 15


def _windowed(pts, moves, step):
    """The matching rule as it was: every move by the window around the last match."""
    match, at = np.zeros(len(moves), int), 0
    for j, m in enumerate(moves):
        at = match[j] = window_match(pts, m, at, step)
    return match


def test_moves_match_the_same_centres():
    """Spirals there and back (far jumps), rounded (ties), shifted off the centres."""
    rng = np.random.default_rng(0)
    for trial in range(60):
        t = np.cumsum(rng.uniform(0, 1, rng.integers(1, 300)))
        pts = np.c_[10 * np.cos(t / 5), 10 * np.sin(t / 5), t / 50]
        if trial % 3 == 0:
            pts = np.round(pts, 1)
        if trial % 5 == 0:
            pts = np.vstack([pts, pts[::-1]])
        moves = pts[np.sort(rng.integers(0, len(pts), rng.integers(1, 200)))]
        moves = moves + rng.normal(0, 0.3, (1, 3)) * (trial % 2)
        if trial % 4 == 0:
            moves = np.vstack([moves, pts[::-1][:50]])
        step = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).max()) if len(pts) > 1 \
            else 1.0
        np.testing.assert_array_equal(_match(pts, moves, step), _windowed(pts, moves, step))


def test_a_slab_finish_gets_the_reference_verdicts():
    """Three passes over finish_slab's B-spline top (ends by its extruded sides), one
    pushed 0.05 mm into the top over 15 cycles: both gates fail that cut alone, alike."""
    part = _load("finish_slab")
    job = Job(Tool(3.0, 0.0), 1500.0, 0.004, Raster((5,), 8.0, None, 0.0, "zigzag"),
              source=str(FIXTURES / "finish_slab.step"))
    program = cadcnc.run(part, job)
    cuts = [s for s in program.segments if s.kind == "cut"][:3]
    tp = cuts[1].path
    points = tp.points.copy()
    points[20:35] -= 0.05 * tp.normals[20:35, 0]
    cuts[1] = CutSegment(dataclasses.replace(tp, points=points))
    seeded = Program(job, cuts, [])
    ref = gate_program(seeded, part, reference=True)
    with shared_gates(part):
        fast = gate_program(seeded, part)
    assert [r.ok for r in ref.results] == [True, False, True]
    for a, b in zip(ref.results, fast.results):
        same(a, b)


def test_a_whole_box_face_answers_by_its_edges_beyond_them():
    """finish_slab's B-spline top is its whole parameter box; points all around it,
    beyond its edges too, get DistShapeShape's distance (unsigned at an edge, as it
    gives it); a face trimmed out of its surface is not taken for its box."""
    part = _load("finish_slab")
    top = FaceProbe(part.face(5).topods, part.tol)
    assert top.natural()
    edges = 0
    for p in _around(top, 60, 5):
        fast, exact = top.interior_distance(p), top.face_distance(p)
        assert fast is not None
        np.testing.assert_allclose(fast, exact, atol=DEPTH)
        edges += fast[0] == fast[1] and exact[0] == exact[1]
    assert edges > 10
    pocket = _load("fillet_pocket")
    assert not all(FaceProbe(pocket.face(k).topods, pocket.tol).natural()
                   for k in range(1, len(pocket) + 1))
