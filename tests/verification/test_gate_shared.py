"""The gate that keeps pace (issue 24) answers as the reference gate does.

The shared and bounded gate (work shared between gates on one part, sampled cycles that
skip OCCT's face distance where bounds rule a nearer point out, closed forms on planar
faces) against ``reference=True`` (the gate as it was): the same verdicts, the same
failing cuts, moves and cycles, and the same depths within 1e-9 mm, on fixture paths and
on seeded gouging programs; the closed forms against OCCT's DistShapeShape.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import cadcnc
from cadcnc.ops.path.pair_path import intersection_path
from cadcnc.program.linking import linked
from cadcnc.program.program import CutSegment, Program
from cadcnc.verification import gate_program, gouge_gate
from cadcnc.verification.cut_back import cut_back
from cadcnc.verification.gate_cache import shared_gates
from cadcnc.verification.probe import FaceProbe
from cadcnc.verification.surface_checks import check_surface
from helpers.fixtures import FIXTURES, fixture_path, load_fixture
from helpers.gate_results import DEPTH, same

_PARTS: dict = {}


def wall_path(end_x: float):
    """stretch_pocket's floor-wall corner run to ``end_x`` without the guard: past x = 32
    the ball cuts the end wall (tests/verification/test_cut_back.py)."""
    if "pocket" not in _PARTS:
        _PARTS["pocket"] = cadcnc.load_step(FIXTURES / "stretch_pocket.step")
    part = _PARTS["pocket"]
    return part, intersection_path(part.face(11), part.face(8), radius=3.0,
                                          feed=1500.0, period=0.004,
                                          start=(10.0, 8.0, 11.0), end=(end_x, 8.0, 11.0))


def pushed(tp, depth: float, at: slice):
    """A copy of ``tp`` with the centres of ``at`` moved ``depth`` mm into the first face."""
    points = tp.points.copy()
    points[at] -= depth * tp.normals[at, 0]
    return dataclasses.replace(tp, points=points)


@pytest.mark.parametrize("name, i, j", [("crossing_cylinders", 1, 2), ("narrow_slot", 3, 4),
                                        ("pocket", 7, 16), ("bspline_boss", 4, 5)])
def test_fixture_paths_get_the_reference_verdicts(name, i, j):
    part = load_fixture(name)
    tp = fixture_path(name, i, j, radius=1.5 if name == "narrow_slot" else 3.0,
                      feed=1500.0, period=0.004)
    ref = gouge_gate(tp, part, reference=True)
    with shared_gates(part):  # the second gate answers from the work of the first
        for moves in (None, np.round(tp.points, 4)):
            same(gouge_gate(tp, part, moves=moves, reference=True) if moves is not None
                 else ref, gouge_gate(tp, part, moves=moves))


def test_seeded_gouges_fail_the_same_cuts_at_the_same_depths():
    """A program of a clean cut, a cut into the end wall, and a cut pushed 0.05 mm into
    the floor over 20 cycles: cut back and gated whole, both gates agree on every cut."""
    part, clean = wall_path(30.0)
    _, wall = wall_path(34.0)
    floor = pushed(clean, 0.05, slice(40, 60))
    program = Program(clean.job, linked([CutSegment(clean), CutSegment(wall),
                                         CutSegment(floor)], 60.0), [])
    ref = gate_program(program, part, reference=True)
    with shared_gates(part):
        fast_back = cut_back(program, part, 60.0)
        fast = gate_program(program, part)
    assert [r.ok for r in ref.results] == [True, False, False]
    for a, b in zip(ref.results, fast.results):
        same(a, b)
    assert [list(c) for c in ref.results[2].hits[0].cycles] == [[40, 59]]  # the seeded cycles
    ref_back = cut_back(program, part, 60.0, reference=True)
    assert [len(c.points) for c in ref_back.cuts] == [len(c.points) for c in fast_back.cuts]
    assert [s.detail for s in ref_back.skipped] == [s.detail for s in fast_back.skipped]


def test_wrong_seeds_are_not_trusted():
    """Seeds pointing at the other end of the face: the bounded check falls back to
    OCCT's distances where the bounds do not hold, and reports what the full one does."""
    part = load_fixture("crossing_cylinders")
    tp = fixture_path("crossing_cylinders", 1, 2, radius=3.0, feed=1500.0, period=0.004)
    probe = FaceProbe(part.face(1).topods)
    seeds = tp.uv[:, 0][::-1].copy()
    out = [check_surface(probe, 1, 3.0, tp.points, seeds, 64, part.tol, bounded=b)
           for b in (False, True)]
    np.testing.assert_allclose(out[0].face_deviation, out[1].face_deviation, atol=DEPTH)
    assert out[0].unseeded_disagreements == out[1].unseeded_disagreements


def test_the_plane_closed_form_is_occts_distance():
    """Random points about planar faces with curved edges (where the closed form runs):
    the same signed and unsigned distances as OCCT's DistShapeShape."""
    compared = 0
    for name in ("finish_boss", "narrow_slot", "pocket"):
        part = cadcnc.load_step(FIXTURES / f"{name}.step")
        lo, hi = part.bounding_box()
        rng = np.random.default_rng(7)
        for k in range(1, len(part) + 1):
            probe = FaceProbe(part.face(k).topods)
            for p in rng.uniform(lo - 4, hi + 4, (12, 3)):
                closed = probe.plane_distance(p)
                if closed is not None:
                    compared += 1
                    np.testing.assert_allclose(closed, probe.face_distance(p), atol=DEPTH)
    assert compared > 30
