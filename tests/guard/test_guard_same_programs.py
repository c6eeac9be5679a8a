"""The guard's cheaper proofs of issue 37 change no program: with them and without them
(OCCT's distance of the whole shank segment to the whole face, no box-tree proof of the
own-face rule, no cell boxes on offset faces) the programs of B-spline and
surface-of-revolution fixtures are the same bytes (program JSON). The pencil programs and
the offset corner (bspline_boss offset by 1 mm, whose run without the offset cells costs
about 25 s) are compared in the slow tier."""

from __future__ import annotations

import math

import pytest
from OCP.BRepOffset import BRepOffset_Skin
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffsetShape
from OCP.GeomAbs import GeomAbs_Intersection

import cadcnc
from cadcnc.core.job import DEFAULT_FEED, DEFAULT_PERIOD, Job, PairPath, Pencil, Tool
from cadcnc.geometry.part import Part
from cadcnc.guard import guard as guard_module
from cadcnc.guard.box_tree import BoxTree
from cadcnc.guard.cells import BOUNDED_KINDS
from cadcnc.guard.clearance import ClearanceGuard
from cadcnc.guard.face_distance import FaceDistance
from cadcnc.io.program_json import program_json
from helpers.fixtures import FIXTURES


def without_new_proofs(monkeypatch) -> None:
    """The guard as before issue 37: whole segments, no rho_above, offsets unbounded,
    DistShapeShape of the whole face."""
    whole = ClearanceGuard._segment_distance
    monkeypatch.setattr(ClearanceGuard, "_segment_distance",
                        lambda self, k, p, length=None, cap=None:
                        whole(self, k, p, length, math.inf))
    monkeypatch.setattr(BoxTree, "rho_above", lambda self, p, z0, need: None)
    monkeypatch.setattr(FaceDistance, "distance", lambda self, p, z0, z1: None)
    monkeypatch.setattr(guard_module, "bounded", lambda face: face.kind in BOUNDED_KINDS)


def both(monkeypatch, part_of, job) -> tuple[str, str]:
    now = program_json(cadcnc.run(part_of(), job))
    with monkeypatch.context() as m:
        without_new_proofs(m)
        before = program_json(cadcnc.run(part_of(), job))
    return now, before


def job_of(operation, radius: float) -> Job:
    return Job(Tool(radius), DEFAULT_FEED, DEFAULT_PERIOD, operation)


@pytest.mark.slow   # 15-30 s each: two pencil programs
@pytest.mark.parametrize("name", ["abc_fold.step", "fillet_pocket.step"])
def test_pencil_programs_unchanged(monkeypatch, name):
    now, before = both(monkeypatch, lambda: cadcnc.load_step(FIXTURES / name),
                       job_of(Pencil(), 3.0))
    assert now == before


def test_bspline_boss_path_unchanged(monkeypatch):
    now, before = both(monkeypatch, lambda: cadcnc.load_step(FIXTURES / "bspline_boss.step"),
                       job_of(PairPath(faces=(4, 5)), 3.0))
    assert now == before


@pytest.mark.slow
def test_offset_corner_unchanged(monkeypatch):
    def offset_boss():
        maker = BRepOffsetAPI_MakeOffsetShape()
        maker.PerformByJoin(cadcnc.load_step(FIXTURES / "bspline_boss.step").shape, 1.0,
                            1e-6, BRepOffset_Skin, False, False, GeomAbs_Intersection)
        return Part(maker.Shape())
    now, before = both(monkeypatch, offset_boss, job_of(PairPath(faces=(4, 5)), 2.0))
    assert now == before
