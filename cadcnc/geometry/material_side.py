"""Where the material is on a surface model: the rule per shell, and the faces it orients.

- A **solid** (as read): its inside.
- A **closed shell**: the volume it encloses; it is made a solid (``BRepBuilderAPI_MakeSolid``
  then ``BRepLib::OrientClosedSolid``, which turns the shell so the volume is finite). A
  closed shell inside another (an odd number of others) is a void of the solid around it,
  as in a solid with an inner cavity.
- An **open shell**: the side its faces' normals point away from, the normals chosen so
  that most of the area faces the tool axis +Z: the shell is reversed when its
  area-weighted normal z component, the flux F = sum over faces of the integral of n.z dA
  (mm^2, from OCCT's triangulation), is negative. A shell with |F| below
  :data:`LEVEL_FRACTION` of its area (a vertical wall, half a horizontal tube) has no side
  facing +Z: its normals stay as in the file, and the rule says so.
- ``flip`` (``--flip-material``) inverts the material side of every face.

The outward (cutter-side) normal of a face is then r_u x r_w times the orientation sign of
the face as it lies in the model, which is what :class:`FaceSurface` already reads.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.BRepLib import BRepLib
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.TopAbs import TopAbs_FACE, TopAbs_IN, TopAbs_SHELL, TopAbs_VERTEX
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Compound
from OCP.TopTools import TopTools_IndexedMapOfShape

from .mesh import face_triangles
from .sewing import Sewn

SOLID = "solid"
CLOSED_SHELL = "closed shell"
OPEN_SHELL = "open shell: normals chosen to face +Z"
OPEN_LEVEL = "open shell: no side faces +Z, normals as in the file"
VOID = "closed shell: a void inside another (material around it)"
FLIPPED = "flipped by --flip-material"
LEVEL_FRACTION = 1e-3
"""|F| / area below this: the open shell faces neither +Z nor -Z (the file's normals kept)."""
NESTED = 1e-7
"""Boundary tolerance (mm) of the classifier that tells whether a shell lies in another."""
NESTED_VERTICES = 64
"""At most this many vertices of a shell are classified to call it nested in another."""
MESH_DEFLECTION = 0.01
"""Relative linear deflection of the triangulation the flux F is summed on (a sign test)."""


@dataclass
class ShellSide:
    """One shell of a surface model: its face numbers, whether it is closed, the rule that
    chose its material side, and for an open shell the flux F (mm^2) and area (mm^2)."""

    faces: list[int]
    closed: bool
    rule: str
    flux_mm2: float = float("nan")
    area_mm2: float = float("nan")

    def to_dict(self) -> dict:
        out = {"faces": list(self.faces), "closed": self.closed, "rule": self.rule}
        if not self.closed:
            out.update(flux_mm2=round(self.flux_mm2, 6), area_mm2=round(self.area_mm2, 6))
        return out


@dataclass
class SurfaceModel:
    """A sewn surface model with its material side: ``shape`` (a compound of the solids
    made of closed shells and the oriented open shells), ``faces`` (the oriented faces in
    the file's order: face n is ``faces[n - 1]``), ``shells`` and the sewing figures."""

    shape: object
    faces: list
    shells: list[ShellSide]
    sewn: Sewn = field(repr=False)

    @property
    def closed(self) -> bool:
        """True when every shell is closed (the material is a set of solids)."""
        return all(s.closed for s in self.shells)


def flux_z(shell) -> tuple[float, float]:
    """(F, A): the integral of n.z over the shell's faces as oriented in it, and its area,
    mm^2, summed over OCCT's triangulation (n the face's outward normal)."""
    BRepMesh_IncrementalMesh(shell, MESH_DEFLECTION, True, 0.5, False)
    flux = area = 0.0
    exp = TopExp_Explorer(shell, TopAbs_FACE)
    while exp.More():
        tris = face_triangles(TopoDS.Face_s(exp.Current()))
        exp.Next()
        if tris is None:
            continue
        a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
        cross = np.cross(b - a, c - a)
        flux += 0.5 * float(cross[:, 2].sum())
        area += 0.5 * float(np.linalg.norm(cross, axis=1).sum())
    return flux, area


def material_sides(sewn: Sewn) -> SurfaceModel:
    """Choose each shell's material side by the rules of the module docstring (the flip of
    ``--flip-material`` is the part's: :class:`cadcnc.geometry.part.Part`)."""
    builder = BRep_Builder()
    compound = TopoDS_Compound()
    builder.MakeCompound(compound)
    closed = [BRep_Tool.IsClosed_s(shell) for shell in sewn.shells]
    solids, voids = _solids([s for s, c in zip(sewn.shells, closed) if c])
    for solid in solids:
        builder.Add(compound, solid)
    voids = iter(voids)
    sides = []
    for shell, numbers, is_closed in zip(sewn.shells, sewn.numbers, closed):
        if is_closed:
            sides.append(ShellSide(sorted(numbers), True, VOID if next(voids) else CLOSED_SHELL))
            continue
        flux, area = flux_z(shell)
        rule = OPEN_SHELL
        if abs(flux) < LEVEL_FRACTION * area:
            rule = OPEN_LEVEL
        elif flux < 0:
            shell, flux = TopoDS.Shell_s(shell.Reversed()), -flux
        builder.Add(compound, shell)
        sides.append(ShellSide(sorted(numbers), False, rule, flux, area))
    faces = oriented_faces(compound, sewn)
    return SurfaceModel(compound, faces, sides, sewn)


def _solids(shells: list) -> tuple[list, list[bool]]:
    """(solids, void flag per shell) of closed shells: each shell bounds a finite volume;
    one nested in an odd number of others is a void of the one directly around it (the
    nesting depth's parity, so an island inside a void is material again)."""
    finite = []
    for shell in shells:
        solid = BRepBuilderAPI_MakeSolid(shell).Solid()
        BRepLib.OrientClosedSolid_s(solid)
        finite.append(solid)
    within = [[i != j and _inside(finite[j], finite[i]) for i in range(len(finite))]
              for j in range(len(finite))]  # within[j][i]: shell j lies inside solid i
    depth = [sum(row) for row in within]
    void = [d % 2 == 1 for d in depth]
    solids = []
    for i, outer in enumerate(finite):
        if void[i]:
            continue
        maker = BRepBuilderAPI_MakeSolid(_shell_of(outer))
        for j, inner in enumerate(finite):
            if void[j] and within[j][i] and depth[j] == depth[i] + 1:
                maker.Add(TopoDS.Shell_s(_shell_of(inner).Reversed()))
        solids.append(maker.Solid())
    return solids, void


def _shell_of(solid):
    """The (only) shell of a solid made of one shell, as oriented in it."""
    return TopoDS.Shell_s(TopExp_Explorer(solid, TopAbs_SHELL).Current())


def _inside(inner, outer) -> bool:
    """Whether the closed shell of solid ``inner`` lies inside solid ``outer``: its box
    inside the other's and every one of its vertices (up to :data:`NESTED_VERTICES`)
    classified IN, so that two bodies that merely overlap are not taken for a void."""
    lo_i, hi_i = _box(inner)
    lo_o, hi_o = _box(outer)
    if np.any(lo_i < lo_o) or np.any(hi_i > hi_o):
        return False
    vertices = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(inner, TopAbs_VERTEX, vertices)
    classifier = BRepClass3d_SolidClassifier(outer)
    for k in range(1, min(vertices.Extent(), NESTED_VERTICES) + 1):
        classifier.Perform(BRep_Tool.Pnt_s(TopoDS.Vertex_s(vertices.FindKey(k))), NESTED)
        if classifier.State() != TopAbs_IN:
            return False
    return True


def _box(shape) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of OCCT's bounding box of a shape (enlarged by its tolerances), mm."""
    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    xmin, ymin, zmin, xmax, ymax, zmax = box.Get()
    return np.array([xmin, ymin, zmin]), np.array([xmax, ymax, zmax])


def oriented_faces(shape, sewn: Sewn) -> list:
    """The faces of ``shape`` as oriented in it, in the file's order (face n at n - 1)."""
    faces = [None] * sewn.n_faces
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        k = sewn.face_map.FindIndex(exp.Current())
        if k and faces[k - 1] is None:
            faces[k - 1] = exp.Current()
        exp.Next()
    return faces
