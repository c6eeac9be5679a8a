"""Pencil on surface models (issue 12): a STEP file with shells or loose faces and no solid
gives a verified program, the same as the solid's."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt

import cadcnc
from cadcnc.io.program_json import read_program
from cadcnc.verification import gouge_gate
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES
from helpers.programs import pencil_run

RADIUS = 2.0


def occt_distance(face, p) -> float:
    """Distance (mm) from point p to a trimmed face, OCCT's BRepExtrema (not cadcnc's)."""
    v = BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex()
    dss = BRepExtrema_DistShapeShape(v, face)
    assert dss.IsDone()
    return dss.Value()


@pytest.fixture(scope="module")
def sheet(tmp_path_factory):
    """`cadcnc pencil` on the open sheet (a B-spline floor and a wall, no solid)."""
    out = tmp_path_factory.mktemp("surf") / "sheet.json"
    run = cadcnc_cli("pencil", FIXTURES / "surf_sheet.step", "--radius", RADIUS, "-o", out,
                     check=0)
    return cadcnc.load_step(FIXTURES / "surf_sheet.step"), read_program(out), run


def test_open_sheet_pencil_is_a_verified_program(sheet):
    """The sheet's one concave corner is cut end to end: every cut point R' from both
    faces (OCCT distance, 1 um), no move of the program (links included) gouges."""
    part, prog, run = sheet
    assert "complete" in run.stdout
    (cut,) = prog.cuts
    assert cut.path.faces == (1, 2)
    # the wall stands on the floor's edge x = 0, y 0..30: the corner's whole length
    assert np.ptp(cut.points[:, 1]) > 30.0 - 2 * RADIUS - 1e-3
    for n in cut.path.faces:
        d = np.array([occt_distance(part.face(n).topods, p) for p in cut.points[::10]])
        assert np.abs(d - RADIUS).max() < 1e-3, n
    gate = gouge_gate(cut.path, part, moves=prog.all_moves())
    assert gate.ok, gate.message


@pytest.fixture(scope="module")
def solid():
    return pencil_run(cadcnc.load_step(FIXTURES / "surf_boss_solid.step"), radius=RADIUS)


@pytest.mark.parametrize("name", ["surf_boss_shell", "surf_boss_faces"])
def test_shell_and_loose_faces_give_the_solids_program(name, solid):
    """The boss as a closed shell, and as loose faces sewn on reading, give the cuts of
    the same part as a solid (face numbers survive sewing)."""
    part = cadcnc.load_step(FIXTURES / f"{name}.step")
    prog = pencil_run(part, radius=RADIUS)
    assert [c.path.faces for c in prog.cuts] == [c.path.faces for c in solid.cuts] != []
    for a, b in zip(prog.cuts, solid.cuts):
        assert a.points.shape == b.points.shape
        np.testing.assert_allclose(a.points, b.points, atol=1e-6)
    assert prog.complete
    gate = gouge_gate(prog.cuts[0].path, part, moves=prog.all_moves())
    assert gate.ok, gate.message
