"""Surface models (STEP shells, loose faces): sewing, face numbers, orientation, material.

Fixtures: fixtures/build_surface_models.py; the sidecar's facts (face kinds, areas,
centroids in the file's own order) were measured on the files as OCCT's reader returns
them, with no cadcnc code.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_Copy,
    BRepBuilderAPI_MakeVertex,
    BRepBuilderAPI_Transform,
)
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepGProp import BRepGProp
from OCP.gp import gp_Pnt, gp_Trsf, gp_Vec
from OCP.GProp import GProp_GProps
from OCP.TopoDS import TopoDS_Compound

import cadcnc
from cadcnc.core.tolerances import DEFAULT
from cadcnc.geometry.faces_report import faces_report
from cadcnc.geometry.material_side import CLOSED_SHELL, FLIPPED, OPEN_LEVEL, OPEN_SHELL, VOID
from cadcnc.geometry.sewing import file_faces, inconsistent_edges, sew
from cadcnc.geometry.step_file import read_step
from cadcnc.ops.path.pair_path import intersection_path
from cadcnc.verification import gouge_gate
from cadcnc.verification.material import IN, OUT, Material, PartFaces
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

SIDE = json.loads((FIXTURES / "surface_models.json").read_text())
BOSS = ["surf_boss_solid", "surf_boss_shell", "surf_boss_faces"]
_parts: dict = {}


def part_of(name: str, flip: bool = False):
    if (name, flip) not in _parts:
        _parts[name, flip] = cadcnc.load_step(FIXTURES / SIDE[name]["file"],
                                              flip_material=flip)
    return _parts[name, flip]


def centroid_and_area(face) -> tuple[np.ndarray, float]:
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face.topods, props)
    return np.array(props.CentreOfMass().Coord()), props.Mass()


def middle(face) -> tuple[float, float]:
    return 0.5 * sum(face.u_range), 0.5 * sum(face.w_range)


@pytest.mark.parametrize("name", sorted(SIDE))
def test_face_numbers_are_the_files_own_after_sewing(name):
    facts, part = SIDE[name], part_of(name)
    assert len(part) == facts["n_faces"]
    assert part.material_rule == facts["rule"]
    for n, fact in enumerate(facts["faces"], 1):
        c, area = centroid_and_area(part.face(n))
        assert part.face(n).kind == fact["kind"], n
        assert area == pytest.approx(fact["area"], abs=1e-5), n
        assert np.allclose(c, fact["centroid"], atol=1e-5), n
    assert inconsistent_edges(part.shape) == 0


def test_sewing_replaces_the_faces_and_maps_them_back():
    shape, _ = read_step(str(FIXTURES / SIDE["surf_boss_faces"]["file"]))
    original = file_faces(shape)
    sewn = sew(shape, DEFAULT.sewing)
    replaced = [k for k in range(1, original.Extent() + 1)
                if not sewn.face_map.FindKey(k).IsSame(original.FindKey(k))]
    assert replaced  # the mapping is exercised: sewing made new faces
    assert sewn.free_edges == 0 and len(sewn.shells) == 1
    assert sorted(sewn.numbers[0]) == list(range(1, original.Extent() + 1))
    assert sewn.edge_tolerance <= DEFAULT.sewing


def test_loose_faces_written_reversed_get_the_solids_normals():
    solid, loose = part_of("surf_boss_solid"), part_of("surf_boss_faces")
    assert SIDE["surf_boss_faces"]["reversed_in_file"] == [2, 5]
    for n in range(1, len(solid) + 1):
        u, w = middle(solid.face(n))
        assert np.allclose(loose.face(n).normal(u, w), solid.face(n).normal(u, w),
                           atol=1e-12), n
    assert solid.concave_pairs() == loose.concave_pairs() == [tuple(SIDE[BOSS[0]]["pair"])]


def test_solid_closed_shell_and_loose_faces_give_the_same_path():
    paths = {}
    for name in BOSS:
        part = part_of(name)
        i, j = SIDE[name]["pair"]
        paths[name] = tp = intersection_path(part.face(i), part.face(j), radius=3,
                                                    feed=1500, period=0.004)
        assert len(tp.points) > 100 and tp.complete
        assert gouge_gate(tp, part).ok, name
    ref = paths[BOSS[0]].points
    for name in BOSS[1:]:
        assert paths[name].points.shape == ref.shape
        assert np.abs(paths[name].points - ref).max() <= 1e-9, name
    assert part_of("surf_boss_shell").material_rule == CLOSED_SHELL


def test_open_sheet_faces_up_and_its_corner_path_passes_the_gate():
    part = part_of("surf_sheet")
    floor, wall = part.face(1), part.face(2)
    assert (floor.kind, wall.kind) == ("bspline", "extrusion")
    u, w = middle(floor)
    assert floor.normal(u, w)[2] > 0.99  # the file's normal pointed down: chosen to face +Z
    u, w = middle(wall)
    assert np.allclose(wall.normal(u, w), [1, 0, 0], atol=1e-9)  # toward the floor
    assert part.pair_class(1, 2) == "concave"
    shell, = part.surface_model.shells
    assert not shell.closed and shell.rule == OPEN_SHELL and shell.flux_mm2 > 0
    sheet = SIDE["surf_sheet"]["sheet"]
    # closed form: the floor's projection on XY is x1 * y1 (the flux of n.z)
    assert shell.flux_mm2 == pytest.approx(sheet["x1"] * sheet["y1"], rel=1e-3)
    tp = intersection_path(floor, wall, radius=3, feed=1500, period=0.004)
    assert tp.complete and len(tp.points) > 100
    assert np.allclose(tp.points[:, 0], 3.0, atol=1e-6)  # R from the wall x = 0
    gate = gouge_gate(tp, part)  # measured: 1.8e-6 mm into the B-spline floor
    assert gate.ok and gate.depth_mm < DEFAULT.accuracy


def sheet_z(x, y):
    s = SIDE["surf_sheet"]["sheet"]
    return s["bow"] * (x / s["x1"]) ** 2 + s["wave"] * (1 - math.cos(2 * math.pi * y / s["y1"]))


@pytest.mark.parametrize("flip", [False, True])
def test_open_sheet_material_by_the_faces_rule(flip):
    part = part_of("surf_sheet", flip)
    material = Material(PartFaces(part, {}, DEFAULT), DEFAULT)
    assert material.kind == "faces"
    h = sheet_z(20, 15)
    probes = {  # point: in the material (below the floor, behind the wall)?
        "above the floor": ((20, 15, h + 2), False),
        "below the floor": ((20, 15, h - 2), True),
        "behind the wall": ((-2, 15, 8), True),
        "in the concave wedge (nearest point the edge)": ((-2, 15, sheet_z(0, 15) - 2), True),
        "over the corner": ((2, 15, sheet_z(0, 15) + 2), False),
    }
    for what, (p, inside) in probes.items():
        assert material.state(p) == (IN if inside != flip else OUT), what


def test_flip_material_inverts_normals_classes_and_rule():
    part, flipped = part_of("surf_sheet"), part_of("surf_sheet", True)
    u, w = middle(part.face(1))
    assert np.allclose(flipped.face(1).normal(u, w), -part.face(1).normal(u, w))
    assert flipped.pair_class(1, 2) == "convex" and flipped.concave_pairs() == []
    assert flipped.material_rule == f"{OPEN_SHELL}; {FLIPPED}"
    solid, as_read = part_of("surf_boss_solid", True), part_of("surf_boss_solid")
    assert solid.material_rule == f"solid; {FLIPPED}"
    swap = {"concave": "convex", "convex": "concave", "tangent": "tangent"}
    assert {p: swap[as_read.pair_class(*p)] for p in as_read.adjacency} == \
        {p: solid.pair_class(*p) for p in solid.adjacency}
    material = Material(PartFaces(solid, {}, DEFAULT), DEFAULT)
    assert material.kind == "solid"
    assert (material.state((5, -3, 10)), material.state((0, 0, 200))) == (OUT, IN)


def _box_faces_with_gap(gap: float):
    import cadquery as cq

    box = cq.Workplane().box(20, 20, 10).val().wrapped
    fmap = file_faces(box)
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    top = max(range(1, fmap.Extent() + 1),
              key=lambda k: centroid_and_area(cadcnc.geometry.face_surface.FaceSurface(
                  fmap.FindKey(k)))[0][2])
    lift = gp_Trsf()
    lift.SetTranslation(gp_Vec(0, 0, gap))
    for k in range(1, fmap.Extent() + 1):
        copy = BRepBuilderAPI_Copy(fmap.FindKey(k)).Shape()
        if k == top:
            copy = BRepBuilderAPI_Transform(copy, lift, True).Shape()
        builder.Add(compound, copy)
    return compound, top


def test_a_gap_within_the_sewing_tolerance_is_closed_and_reported():
    compound, top = _box_faces_with_gap(5e-4)
    part = cadcnc.Part(compound)
    assert part.material_rule == CLOSED_SHELL and len(part) == 6
    report = faces_report(part)["material"]
    assert 2e-4 <= report["sewing"]["max_edge_tolerance_mm"] <= DEFAULT.sewing
    assert report["sewing"]["free_edges"] == 0
    assert part.face(top).normal(*middle(part.face(top)))[2] == pytest.approx(1.0)
    assert all(part.pair_class(*p) == "convex" for p in part.adjacency)
    # below the gap, the lifted top stays apart: two open shells
    apart = cadcnc.Part(compound, tol=DEFAULT.__class__(sewing=1e-5))
    assert [s.closed for s in apart.surface_model.shells] == [False, False]
    assert len(apart.adjacency) == 8  # the four side faces' edges with the bottom and each other


def cli(*args) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``cadcnc ARGS`` run in this process."""
    run = cadcnc_cli(*args)
    return run.returncode, run.stdout, run.stderr


def test_cli_faces_says_which_rule_applied():
    sheet = FIXTURES / SIDE["surf_sheet"]["file"]
    code, out, _ = cli("faces", sheet)
    assert code == 0 and f"material side: {OPEN_SHELL}" in out
    assert "sewn at 0.01 mm" in out and "6 free edges" in out
    code, out, _ = cli("faces", sheet, "--flip-material", "--json")
    data = json.loads(out)
    assert code == 0 and data["material"]["rule"] == f"{OPEN_SHELL}; {FLIPPED}"
    assert data["material"]["flipped"] and data["concave_pairs"] == []
    shell, = data["material"]["shells"]
    assert shell["faces"] == [1, 2] and not shell["closed"]
    code, out, _ = cli("faces", FIXTURES / SIDE["surf_boss_solid"]["file"], "--json")
    assert json.loads(out)["material"] == {"rule": "solid", "flipped": False}


def test_cli_path_on_loose_faces_is_verified_on_the_same_material_side(tmp_path):
    loose = FIXTURES / SIDE["surf_boss_faces"]["file"]
    out = tmp_path / "boss.json"
    job = ["--radius", "3", "--feed", "1500", "--period", "4ms"]
    code, _, err = cli("path", loose, "--faces", 4, 5, *job, "-o", out, "-q")
    assert code == 0, err
    saved = json.loads(out.read_text())
    assert saved["job"]["flip_material"] is False
    assert cli("verify", out, "-q")[0] == 0
    # flipped, the boss corner is convex: no path along it
    code, _, err = cli("path", loose, "--faces", 4, 5, *job, "-o", tmp_path / "f.json",
                       "--flip-material")
    assert code != 0 and "convex" in err and not (tmp_path / "f.json").exists()


def test_a_vertical_sheet_faces_neither_way_and_keeps_the_files_normals():
    import cadquery as cq

    for direction in ((1, 0, 0), (-1, 0, 0)):
        part = cadcnc.Part(cq.Face.makePlane(10, 10, dir=direction).wrapped)
        assert part.material_rule == OPEN_LEVEL
        shell, = part.surface_model.shells
        assert abs(shell.flux_mm2) < 1e-9 * shell.area_mm2 + 1e-9
        assert np.allclose(part.face(1).normal(*middle(part.face(1))), direction)


def _shifted(tp, keep, shift):
    sub = {f.name: getattr(tp, f.name)[keep] for f in dataclasses.fields(tp)
           if f.name in ("points", "contacts", "normals", "uv", "steps", "commanded")}
    sub["points"] = sub["points"] + np.asarray(shift, float)
    return dataclasses.replace(tp, **sub, bounds=None)


def _distance_to(shape, points) -> np.ndarray:
    dss = BRepExtrema_DistShapeShape()
    dss.LoadS2(shape)
    out = []
    for p in points:
        dss.LoadS1(BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex())
        dss.Perform()
        out.append(dss.Value())
    return np.array(out)


@pytest.mark.parametrize("shift, inside", [
    ((0, 0, -1), False),   # the ball 1 mm into the floor, its centre above it
    ((20, 0, -9), True),   # centres 6 mm under the floor, far from the wall
    ((-5, 0, -5), True),   # behind the wall and under the floor: nearest point the edge
], ids=["cut", "under the floor", "in the wedge"])
def test_the_gate_refuses_an_open_sheet_path_in_its_material(shift, inside):
    part = part_of("surf_sheet")
    tp = intersection_path(part.face(1), part.face(2), radius=3, feed=1500,
                                  period=0.004)
    keep = np.nonzero(np.abs(tp.points[:, 1] - 15) <= 5)[0]
    bad = _shifted(tp, keep, shift)
    gate = gouge_gate(bad, part)
    assert not gate.ok and gate.in_material == inside
    d = _distance_to(part.shape, bad.points)  # OCCT's distance to the whole sheet
    expected = 3 + d.max() if inside else 3 - d.min()
    at_centres = max(h.depth_mm for h in gate.hits)  # the moves' sag may add a little
    assert at_centres == pytest.approx(expected, abs=1e-6)
    assert expected - 1e-6 <= gate.depth_mm <= expected + 1e-3


def test_a_closed_shell_inside_another_is_a_void():
    """A block with a closed inner cavity, as loose faces: the cavity's shell is a void of
    the block (as in the solid), not a second body; an island inside the void is material."""
    import cadquery as cq

    solid = (cq.Workplane().box(40, 40, 40).cut(cq.Workplane().box(20, 20, 20))
             .union(cq.Workplane().box(6, 6, 6))).val().wrapped
    by_faces = cadcnc.Part(_loose_copy(solid))
    rules = sorted(s.rule for s in by_faces.surface_model.shells)
    assert rules == [CLOSED_SHELL, CLOSED_SHELL, VOID]
    as_solid = cadcnc.Part(solid)
    assert {p: as_solid.pair_class(*p) for p in as_solid.adjacency} == \
        {p: by_faces.pair_class(*p) for p in by_faces.adjacency}
    assert "concave" in {by_faces.pair_class(*p) for p in by_faces.adjacency}  # the cavity
    material = Material(PartFaces(by_faces, {}, DEFAULT), DEFAULT)
    states = [material.state(p) for p in ((15, 0, 0), (7, 0, 0), (0, 0, 0), (30, 0, 0))]
    assert states == [IN, OUT, IN, OUT]  # wall, cavity, island, outside


def _loose_copy(shape) -> TopoDS_Compound:
    fmap = file_faces(shape)
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    for k in range(1, fmap.Extent() + 1):
        builder.Add(compound, BRepBuilderAPI_Copy(fmap.FindKey(k)).Shape())
    return compound
