"""A B-rep part: faces numbered 1..N as CAD users know them, and which faces meet how.

Faces are numbered in ``TopExp::MapShapes`` order, the numbers FreeCAD shows as
Face1..FaceN. Every pair of faces sharing an edge is classified from the dihedral angle
sampled along the edge, measured through the material: < 180 deg convex (outer corner),
~180 deg tangent/smooth, > 180 deg concave (inner corner: a ball can sit in it, the pair a
pencil path follows). This module and face_surface are the only ones that read topology.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d
from OCP.GCPnts import GCPnts_AbscissaPoint
from OCP.gp import gp_Pnt, gp_Vec
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED, TopAbs_SOLID
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Shape
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

from ..core.errors import FaceNumberError, InputError, StepFileError
from ..core.tolerances import DEFAULT, Tolerances
from .differential import cross
from .face_surface import FaceSurface
from .material_side import FLIPPED, SOLID, SurfaceModel, material_sides
from .sewing import file_faces, sew
from .step_file import read_step

CONCAVE, CONVEX, TANGENT, MIXED = "concave", "convex", "tangent", "mixed"


@dataclass
class SharedEdge:
    """An edge shared by two faces, with its classification seen from outside the material.

    ``angles_deg`` are the material-side dihedral angles at the samples (mm-free).
    ``points`` (k, 3) are the sample points in mm; ``closed`` says the edge is a loop.
    """

    faces: tuple[int, int]
    edge: object = field(repr=False)
    edge_class: str
    angles_deg: np.ndarray = field(repr=False)
    points: np.ndarray = field(repr=False)
    length: float
    closed: bool
    start: np.ndarray = field(repr=False, default=None)
    end: np.ndarray = field(repr=False, default=None)
    start_tangent: np.ndarray = field(repr=False, default=None)
    end_tangent: np.ndarray = field(repr=False, default=None)

    @property
    def angle_range_deg(self) -> tuple[float, float]:
        return float(self.angles_deg.min()), float(self.angles_deg.max())


def load_step(path: str | os.PathLike, tol: Tolerances = DEFAULT,
              flip_material: bool = False) -> "Part":
    """Read a STEP file into a :class:`Part`; errors name the file and the problem.

    What OCCT's reader printed is kept in ``part.warnings`` (never on standard output).
    A surface model (no solid) is sewn and given a material side (:class:`Part`).
    """
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"path must be a STEP file's path, got {type(path).__name__}")
    path = os.fspath(path)
    shape, warnings = read_step(path)
    part = Part(shape, source=path, tol=tol, flip_material=flip_material)
    part.warnings = warnings
    return part


def _shape_of(obj) -> TopoDS_Shape:
    """A TopoDS_Shape from a CadQuery Workplane, Shape or Assembly, or an OCP shape."""
    if hasattr(obj, "vals") and hasattr(obj, "toOCC"):  # cq.Workplane
        vals = obj.vals()
        if len(vals) == 1:
            return _shape_of(vals[0])
        import cadquery as cq  # ~2.3 s to import: only CadQuery users, who have it loaded

        return cq.Compound.makeCompound([v for v in vals if hasattr(v, "wrapped")]).wrapped
    if hasattr(obj, "toCompound"):  # cq.Assembly
        return obj.toCompound().wrapped
    shape = getattr(obj, "wrapped", obj)
    if not isinstance(shape, TopoDS_Shape):
        raise StepFileError(
            f"cannot machine a {type(obj).__name__}: give a CadQuery Workplane, Shape or "
            "Assembly, an OCP TopoDS_Shape, or a STEP file (a Sketch is 2-D: extrude it "
            "first)")
    return shape


class Part:
    """Faces (1-based), adjacency and edge classes of a solid or a surface model.

    A shape without a solid (shells, loose faces) is sewn at ``tol.sewing`` and each shell
    given a material side (:mod:`.material_side`); ``surface_model`` keeps the shells, the
    rules and the sewing figures (None for a solid), and ``shape`` becomes the sewn model.
    Face numbers are always the ``TopExp::MapShapes`` order of the shape as given. ``flip_material`` inverts the material side of every
    face; ``material_rule`` says which rule applied.
    """

    def __init__(self, shape, source: str = "<shape>", tol: Tolerances = DEFAULT,
                 flip_material: bool = False):
        self.shape = _shape_of(shape)
        self.given_shape = self.shape   # as given, before sewing (a setup turns this one; a worker rebuilds from it)
        self.source = source
        self.tol = tol
        self.flip_material = bool(flip_material)
        self.surface_model: SurfaceModel | None = None
        if self.shape is None or self.shape.IsNull():
            raise StepFileError(f"{source}: holds no shape")
        fmap = file_faces(self.shape)
        if fmap.Extent() == 0:
            raise StepFileError(f"{source}: holds no faces (cadcnc machines solids and "
                                "surface models)")
        if TopExp_Explorer(self.shape, TopAbs_SOLID).More():
            faces = [fmap.FindKey(k) for k in range(1, fmap.Extent() + 1)]
            self.material_rule = SOLID
        else:
            self.surface_model = material_sides(sew(self.shape, tol.sewing, source))
            self.shape = self.surface_model.shape
            faces = self.surface_model.faces
            self.material_rule = "; ".join(dict.fromkeys(
                s.rule for s in self.surface_model.shells))
        if self.flip_material:
            faces = [f.Reversed() for f in faces]
            self.material_rule += f"; {FLIPPED}"
        self._fmap = TopTools_IndexedMapOfShape()
        for f in faces:
            self._fmap.Add(f)
        self._faces: dict[int, FaceSurface] = {}
        self._edges: dict[tuple[int, int], list[SharedEdge]] | None = None
        self._emap: TopTools_IndexedDataMapOfShapeListOfShape | None = None
        self._bbox: tuple[np.ndarray, np.ndarray] | None = None
        self._face_boxes: tuple[np.ndarray, np.ndarray] | None = None
        self.derived: dict = {}
        """What other stages build once from this part (its turned setups, the guards'
        face data, the gates' shared work), by its owner's key (the owner's module name):
        kept with the part, dropped with it."""
        self.warnings: list[str] = []  # what OCCT printed while reading the file

    @classmethod
    def from_cadquery(cls, obj, tol: Tolerances = DEFAULT) -> "Part":
        """A part from a CadQuery Workplane or Shape (or an OCP TopoDS_Shape)."""
        return cls(obj, source=f"<{type(obj).__name__}>", tol=tol)

    def __repr__(self) -> str:
        return f"<Part {self.source}: {len(self)} faces>"

    def __len__(self) -> int:
        return self._fmap.Extent()

    def face(self, number: int) -> FaceSurface:
        """Face ``number`` (1-based, FreeCAD's FaceN)."""
        if isinstance(number, bool) or not isinstance(number, (int, np.integer)) \
                or not 1 <= number <= len(self):
            shown = number if isinstance(number, (int, np.integer)) and not isinstance(
                number, bool) else repr(number)
            raise FaceNumberError(
                f"{self.source}: face number {shown} out of range: the part has faces "
                f"1..{len(self)}")
        number = int(number)
        if number not in self._faces:
            self._faces[number] = FaceSurface(
                TopoDS.Face_s(self._fmap.FindKey(number)), number, self.tol, part=self)
        return self._faces[number]

    @property
    def faces(self) -> list[FaceSurface]:
        return [self.face(i) for i in range(1, len(self) + 1)]

    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo (3,), hi (3,)) of the part's optimal axis-aligned bounding box, mm."""
        if self._bbox is None:
            lo, hi = self.face_boxes()
            self._bbox = lo.min(axis=0), hi.max(axis=0)
        return self._bbox

    def face_boxes(self) -> tuple[np.ndarray, np.ndarray]:
        """(lows (n, 3), highs (n, 3)) of every face's optimal box (mm; face k at row k - 1),
        computed once: the part's box is their union, and the guards share them."""
        if self._face_boxes is None:
            boxes = [self.face(k).box() for k in range(1, len(self) + 1)]
            self._face_boxes = (np.array([b[0] for b in boxes]).reshape(-1, 3),
                                np.array([b[1] for b in boxes]).reshape(-1, 3))
        return self._face_boxes

    @property
    def top(self) -> float:
        """Highest Z of the part, mm (rapid moves clear it by a margin)."""
        return float(self.bounding_box()[1][2])

    def face_number(self, face) -> int:
        """The 1-based number of a TopoDS/CadQuery face of this part (0 if not found)."""
        return self._fmap.FindIndex(getattr(face, "wrapped", face))

    # -- adjacency -------------------------------------------------------------------------
    @property
    def adjacency(self) -> dict[tuple[int, int], list[SharedEdge]]:
        """{(i, j): shared edges} for every pair i < j of faces that share an edge."""
        if self._edges is None:
            self._edges = self._classify_edges()
        return self._edges

    @property
    def adjacency_known(self) -> bool:
        """Whether :attr:`adjacency` is computed (or taken) already."""
        return self._edges is not None

    def take_adjacency(self, edges: dict[tuple[int, int], list[SharedEdge]]) -> None:
        """Use ``edges`` as :attr:`adjacency` instead of classifying: those of a copy of this
        part, with this part's own edge objects (:mod:`.part_bytes`)."""
        self._edges = edges

    def shared_edges(self, i: int, j: int) -> list[SharedEdge]:
        self.face(i), self.face(j)
        return self.adjacency.get((min(i, j), max(i, j)), [])

    def pair_class(self, i: int, j: int) -> str | None:
        """concave/convex/tangent/mixed for adjacent faces, None if they share no edge."""
        classes = {e.edge_class for e in self.shared_edges(i, j)}
        if not classes:
            return None
        return classes.pop() if len(classes) == 1 else MIXED

    def neighbours(self, n: int) -> dict[int, list[SharedEdge]]:
        self.face(n)
        out: dict[int, list[SharedEdge]] = {}
        for (i, j), edges in self.adjacency.items():
            if n in (i, j):
                out[j if i == n else i] = edges
        return out

    def concave_pairs(self) -> list[tuple[int, int]]:
        """Pairs whose every shared edge is concave: the candidates for an intersection path."""
        return [pair for pair in self.adjacency if self.pair_class(*pair) == CONCAVE]

    def edge_map(self) -> TopTools_IndexedDataMapOfShapeListOfShape:
        """Every edge of ``shape`` -> the faces holding it, in OCCT's
        ``TopExp::MapShapesAndAncestors`` order (built once): edge k of the adjacency."""
        if self._emap is None:
            self._emap = TopTools_IndexedDataMapOfShapeListOfShape()
            TopExp.MapShapesAndAncestors_s(self.shape, TopAbs_EDGE, TopAbs_FACE, self._emap)
        return self._emap

    def _classify_edges(self) -> dict[tuple[int, int], list[SharedEdge]]:
        result: dict[tuple[int, int], list[SharedEdge]] = {}
        oriented = self._orientations()
        for k, edge, numbers in self.shared_edge_indices():
            sides = [EdgeSide(oriented.get((k, n)), self.face(n)) for n in numbers]
            shared = self._classify_edge(edge, *numbers, sides)
            result.setdefault((numbers[0], numbers[1]), []).append(shared)
        return dict(sorted(result.items()))

    def shared_edge_indices(self) -> list[tuple[int, object, list[int]]]:
        """(index in :meth:`edge_map`, edge, [i, j]) of every edge two faces i < j share
        (seams, collapsed and non-manifold edges left out)."""
        emap, out = self.edge_map(), []
        for k in range(1, emap.Extent() + 1):
            edge = TopoDS.Edge_s(emap.FindKey(k))
            if BRep_Tool.Degenerated_s(edge):
                continue
            numbers = self._face_numbers(emap.FindFromIndex(k))
            if len(numbers) == 2:
                out.append((k, edge, numbers))
        return out

    def _face_numbers(self, faces) -> list[int]:
        """The sorted distinct numbers of an OCCT list of this part's faces (read by
        First/Last: iterating such a list from Python costs ~0.5 ms)."""
        n = faces.Extent()
        if n == 0:   # a free edge (a wire beside the faces): no face holds it
            return []
        shapes = [faces.First(), faces.Last()][:n] if n <= 2 else list(faces)
        return sorted({self._fmap.FindIndex(f) for f in shapes})

    def _orientations(self) -> dict[tuple[int, int], object]:
        """{(k, n): edge k of :meth:`edge_map` as oriented in face n (its first occurrence
        in the face's wires)}, from one walk over every face's edges."""
        emap, found = self.edge_map(), {}
        for n in range(1, len(self) + 1):
            exp = TopExp_Explorer(self._fmap.FindKey(n), TopAbs_EDGE)
            while exp.More():
                found.setdefault((emap.FindIndex(exp.Current()), n),
                                 TopoDS.Edge_s(exp.Current()))
                exp.Next()
        return found

    def _classify_edge(self, edge, i: int, j: int, sides: list["EdgeSide"],
                       samples: int = 9) -> SharedEdge:
        """The SharedEdge of ``edge`` between faces i < j seen from ``sides`` (its
        :class:`EdgeSide` in face i, then in face j), sampled at ``samples`` parameters."""
        curve = BRepAdaptor_Curve(edge)
        t0, t1 = curve.FirstParameter(), curve.LastParameter()
        ts = t0 + (t1 - t0) * (np.arange(samples) + 0.5) / samples
        angles, points = [], []
        for t in ts:
            p = np.array(curve.Value(t).Coord())
            (d1, n1), (d2, n2) = (side.inward_and_normal(t) for side in sides)
            theta = math.degrees(math.atan2(_norm(cross(d1, d2)), d1 @ d2))
            angles.append(360.0 - theta if d2 @ n1 > 0 else theta)
            points.append(p)
        angles = np.array(angles)
        tangent = np.abs(angles - 180.0) <= self.tol.tangent_edge_deg
        concave = (angles > 180.0) & ~tangent
        convex = (angles < 180.0) & ~tangent
        if concave.any() and convex.any():
            cls = MIXED
        elif concave.any():
            cls = CONCAVE
        elif convex.any():
            cls = CONVEX
        else:
            cls = TANGENT
        length = GCPnts_AbscissaPoint.Length_s(curve)
        (start, t_start), (end, t_end) = _point_and_tangent(curve, t0), _point_and_tangent(curve, t1)
        closed = bool(np.linalg.norm(start - end) < self.tol.closed)
        return SharedEdge((i, j), edge, cls, angles, np.array(points), length, closed,
                          start, end, t_start, t_end)

    @staticmethod
    def inward_and_normal(edge, face: FaceSurface, t: float):
        """(inward direction, outward normal) of ``face`` at edge parameter t
        (:meth:`EdgeSide.inward_and_normal`; an :class:`EdgeSide` kept for many t is
        faster)."""
        return EdgeSide(_oriented_in(edge, face), face).inward_and_normal(t)


class EdgeSide:
    """An edge seen from one of its faces: the edge ``oriented`` as in the face's wires,
    its curve on the face and its 3-D curve, built once for many parameters."""

    def __init__(self, oriented, face: FaceSurface):
        self.face = face
        self.oriented = oriented
        self._uv = BRepAdaptor_Curve2d(oriented, face.topods)
        self._curve = BRepAdaptor_Curve(oriented)
        self._sign = -1.0 if oriented.Orientation() == TopAbs_REVERSED else 1.0

    def inward_and_normal(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """((3,) inward direction, (3,) outward normal) of the face at edge parameter t.

        The face's wires leave the material on the left seen from the normal, so with T
        the edge tangent as oriented in this face, n x T points into the face.
        """
        uv = self._uv.Value(t)
        n = self.face.normal(uv.X(), uv.Y())
        tangent = _point_and_tangent(self._curve, t)[1]
        if self._sign < 0:
            tangent = -tangent
        d = cross(n, tangent)
        return d / _norm(d), n


def _oriented_in(edge, face: FaceSurface):
    """``edge`` as oriented in ``face`` (its first occurrence in the face's wires)."""
    exp = TopExp_Explorer(face.topods, TopAbs_EDGE)
    while exp.More():
        if exp.Current().IsSame(edge):
            return TopoDS.Edge_s(exp.Current())
        exp.Next()
    return None


def _point_and_tangent(curve: BRepAdaptor_Curve, t: float) -> tuple[np.ndarray, np.ndarray]:
    """Point (mm) and unit tangent of an edge curve at parameter t (curve's own direction)."""
    p, v = gp_Pnt(), gp_Vec()
    curve.D1(t, p, v)
    d = np.array(v.Coord())
    return np.array(p.Coord()), d / _norm(d)


def _norm(v: np.ndarray) -> float:
    """|v| of a (3,) float array: np.linalg.norm's value (the square root of v.dot(v))
    without its overhead."""
    return math.sqrt(v.dot(v))
