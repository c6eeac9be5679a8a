"""Part model: face numbering, adjacency and edge classes against the fixtures' sidecar."""

from __future__ import annotations

import cadquery as cq
import pytest
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedMapOfShape

import cadcnc
from cadcnc.core.errors import FaceNumberError, StepFileError
from helpers.fixtures import FIXTURE_NAMES, FIXTURES, SIDECAR, load_fixture


@pytest.mark.parametrize("name", FIXTURE_NAMES)
def test_face_numbering_is_topexp_mapshapes_order(name):
    part = load_fixture(name)
    reader = STEPControl_Reader()
    reader.ReadFile(str(FIXTURES / SIDECAR[name]["file"]))
    reader.TransferRoots()
    fmap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(reader.OneShape(), TopAbs_FACE, fmap)
    assert len(part) == fmap.Extent() == SIDECAR[name]["n_faces"]
    for n in range(1, len(part) + 1):
        ours = part.face(n)
        theirs = BRepAdaptor_Surface(TopoDS.Face_s(fmap.FindKey(n)))
        assert ours.kind == SIDECAR[name]["faces"][str(n)]["kind"]
        assert ours.area() == pytest.approx(SIDECAR[name]["faces"][str(n)]["area"], rel=1e-6)
        assert ours.number == n
        # same surface: the same point at the same parameters
        u, w = sum(ours.u_range) / 2, sum(ours.w_range) / 2
        assert ours.point(u, w) == pytest.approx(list(theirs.Value(u, w).Coord()), abs=1e-9)


@pytest.mark.parametrize("name", FIXTURE_NAMES)
def test_adjacency_and_edge_classes_agree_with_sidecar(name):
    part = load_fixture(name)
    expected = {tuple(p["faces"]): p for p in SIDECAR[name]["pairs"]}
    assert set(part.adjacency) == set(expected)
    for pair, facts in expected.items():
        want = facts["class"]
        if want == "mixed" and facts.get("end_class") == "tangent":
            want = facts["interior_class"]  # concave inside, tangent only at its ends
        assert part.pair_class(*pair) == want, pair
        lo = min(e.angle_range_deg[0] for e in part.shared_edges(*pair))
        hi = max(e.angle_range_deg[1] for e in part.shared_edges(*pair))
        exp_lo, exp_hi = facts["material_angle_deg"]
        # our samples lie inside the edge; the sidecar's include the ends
        assert exp_lo - 1e-6 <= lo <= hi <= exp_hi + 1e-6, (pair, lo, hi, facts)
    concave = {pair for pair in expected if part.pair_class(*pair) == "concave"}
    assert set(part.concave_pairs()) == concave


def test_neighbours_and_shared_edge_geometry():
    part = load_fixture("sphere_cylinder")
    (i, j), = part.concave_pairs()
    assert j in part.neighbours(i) and i in part.neighbours(j)
    edge, = part.shared_edges(i, j)
    assert edge.closed
    radius = SIDECAR["sphere_cylinder"]["pairs"][0]["closed_form"]["cylinder_radius"]
    assert edge.length == pytest.approx(2 * 3.141592653589793 * radius, rel=1e-9)


def test_from_cadquery_matches_workplane_faces():
    wp = cq.Workplane().box(10, 20, 30).faces(">Z").workplane().hole(4, 10)
    part = cadcnc.Part.from_cadquery(wp)
    assert len(part) == len(wp.val().Faces())
    assert part.face_number(wp.faces(">Z").val()) >= 1
    floor_wall = [p for p in part.adjacency if part.pair_class(*p) == "concave"]
    assert len(floor_wall) == 1  # hole floor to hole wall


# -- bad input ------------------------------------------------------------------------------
def test_missing_file(tmp_path):
    with pytest.raises(StepFileError, match="no such file"):
        cadcnc.load_step(tmp_path / "nope.step")


def test_not_a_step_file(tmp_path):
    bad = tmp_path / "notes.step"
    bad.write_text("this is not STEP\n")
    with pytest.raises(StepFileError, match="not a STEP file"):
        cadcnc.load_step(bad)


def test_corrupt_step_file(tmp_path):
    bad = tmp_path / "broken.step"
    bad.write_text("ISO-10303-21;\nHEADER;\nthis is garbage\n")
    with pytest.raises(StepFileError, match=str(bad.name)):
        cadcnc.load_step(bad)


def test_step_with_one_face_is_an_open_surface_model(tmp_path):
    face_only = tmp_path / "face.step"
    cq.exporters.export(cq.Workplane().rect(10, 10).extrude(1).faces(">Z"), str(face_only))
    part = cadcnc.load_step(face_only)
    assert len(part) == 1 and part.material_rule == "open shell: normals chosen to face +Z"
    face = part.face(1)
    u, w = (0.5 * sum(face.u_range), 0.5 * sum(face.w_range))
    assert face.normal(u, w) @ [0, 0, 1] == pytest.approx(1.0, abs=1e-12)


def test_step_with_no_face(tmp_path):
    wire_only = tmp_path / "wire.step"
    cq.exporters.export(cq.Workplane().rect(10, 10), str(wire_only))
    with pytest.raises(StepFileError, match="holds no faces"):
        cadcnc.load_step(wire_only)


@pytest.mark.parametrize("bad", [0, -1, 6, "2", 2.0, None])
def test_face_number_out_of_range(bad):
    part = load_fixture("crossing_cylinders")
    with pytest.raises(FaceNumberError, match=r"1\.\.5"):
        part.face(bad)
