"""Where the material is: the part's faces with their boxes, and which points lie inside.

Membership in the material is a property of the solid, not of one face: a point behind a
face (on its material side) may still be outside the part, past a thin wall or beyond the
face's far edge. :class:`Material` asks OCCT's solid classifier
(``BRepClass3d_SolidClassifier``) of every solid of the part (a closed shell of a surface
model is one: :mod:`cadcnc.geometry.material_side`); a part with an open shell falls
back to the material side of the nearest face (:meth:`Material.side_of_nearest_face`).
With ``--flip-material`` the material is the other side: the classifier's IN and OUT swap. :class:`PartFaces` holds one probe and two boxes per
face: a cheap loose box for all faces (``BRepBndLib::Add``, ~20 us a face) and the
optimal box (``AddOptimal``, ~4 ms a face) only for faces the loose box cannot rule out.
Lengths in mm.
"""

from __future__ import annotations

import math
from contextlib import contextmanager

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.BRepExtrema import BRepExtrema_IsInFace
from OCP.gp import gp_Pnt
from OCP.TopAbs import TopAbs_IN, TopAbs_ON, TopAbs_OUT, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from ..core.tolerances import Tolerances
from .bounds import point_box_distance
from .planar import planar_twin
from .probe import FaceProbe

IN, OUT, ON = "in", "out", "on"
SOLID, FACES = "solid", "faces"
BOX_MARGIN = 1e-6
"""Growth of every optimal box (mm): AddOptimal finds the extent numerically."""
TIE = 1e-6
"""Faces within this (mm) of the nearest distance share its foot point (an edge, a vertex)."""


def _box(shape, optimal: bool) -> tuple[np.ndarray, np.ndarray]:
    box = Bnd_Box()
    if optimal:
        BRepBndLib.AddOptimal_s(shape, box, False, False)
    else:
        BRepBndLib.Add_s(shape, box, False)
    if box.IsVoid():
        return np.full(3, np.inf), np.full(3, -np.inf)
    xmin, ymin, zmin, xmax, ymax, zmax = box.Get()
    return np.array([xmin, ymin, zmin]), np.array([xmax, ymax, zmax])


class PartFaces:
    """Every face of a part: OCCT probes (made when first needed) and bounding boxes.

    ``probes``: probes already made (the pair's), by face number. ``memo``: a dict that
    keeps every exact point-to-face distance of :meth:`distance` by face and point, so
    that gates on the same part share them (None: none kept, the reference gate). Inside
    :meth:`scratch` new distances go to a dict of their own, dropped when it ends (a long
    stream's moves: the memo would grow with every period).
    """

    def __init__(self, part, probes: dict[int, FaceProbe], tol: Tolerances,
                 memo: dict | None = None):
        self.part, self.tol = part, tol
        self.probes = dict(probes)
        self.memo = memo
        self._scratch: dict | None = None
        n = len(part)
        self.loose = np.empty((n + 1, 2, 3))
        self.loose[0, 0], self.loose[0, 1] = np.inf, -np.inf
        for k in range(1, n + 1):
            self.loose[k] = _box(part.face(k).topods, optimal=False)
        self._tight: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._twins: dict[int, FaceProbe | None] = {}

    def __len__(self) -> int:
        return len(self.loose) - 1

    def probe(self, n: int) -> FaceProbe:
        if n not in self.probes:
            face = self.part.face(n)
            self.probes[n] = FaceProbe(face.topods, self.tol, face.box)
        return self.probes[n]

    def distance(self, n: int, point) -> tuple[float, float]:
        """(signed, unsigned) distance from ``point`` to face ``n``
        (:meth:`FaceProbe.face_distance`; on a plane, or a face that is one in all but
        name (:func:`~.planar.planar_twin`), the closed form
        :meth:`FaceProbe.plane_distance`; else an interior foot that OCCT's searches
        prove nearest, :meth:`FaceProbe.interior_distance`), from the memo when the same point was asked
        before (OCCT's answer for the same input: the same numbers)."""
        if self.memo is None:
            return self.probe(n).face_distance(point)
        key = (n, np.asarray(point, float).tobytes())
        found = self.memo.get(key)
        if found is None and self._scratch is not None:
            found = self._scratch.get(key)
        if found is None:
            probe = self.probe(n)
            found = probe.plane_distance(point) or self._twin_distance(n, point) \
                or probe.interior_distance(point) or probe.face_distance(point)
            (self.memo if self._scratch is None else self._scratch)[key] = found
        return found

    @contextmanager
    def scratch(self):
        """Distances computed inside are kept only until it ends (the memo is still read)."""
        before, self._scratch = self._scratch, {}
        try:
            yield
        finally:
            self._scratch = before

    def _twin_distance(self, n: int, point) -> tuple[float, float] | None:
        if n not in self._twins:
            self._twins[n] = planar_twin(self.probe(n), self.tol)
        twin = self._twins[n]
        return None if twin is None else twin.plane_distance(point)

    def box(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """The face's optimal box grown by :data:`BOX_MARGIN` (computed once)."""
        if n not in self._tight:
            lo, hi = self.probe(n).bbox()
            self._tight[n] = lo - BOX_MARGIN, hi + BOX_MARGIN
        return self._tight[n]

    def near(self, lo: np.ndarray, hi: np.ndarray, margin: float) -> list[int]:
        """Faces whose loose box comes within ``margin`` of the box [lo, hi]."""
        gap = np.maximum(np.maximum(np.asarray(lo) - self.loose[1:, 1],
                                    self.loose[1:, 0] - np.asarray(hi)), 0.0)
        return (np.nonzero(np.sqrt((gap * gap).sum(axis=1)) <= margin)[0] + 1).tolist()

    def nearest(self, point) -> tuple[int, float, float]:
        """(face, signed, unsigned distance) of the face nearest to ``point``.

        Branch and bound: faces in order of their loose box's distance, stopping when the
        next box is farther than the best distance found. Signed as
        :meth:`FaceProbe.face_distance` (+ out of the material). (0, nan, nan) when no
        distance could be measured.
        """
        p = np.asarray(point, float)[None]
        lower = point_box_distance(np.repeat(p, len(self), 0), self.loose[1:, 0],
                                   self.loose[1:, 1])
        best = (0, math.nan, math.inf)
        for k in np.argsort(lower, kind="stable") + 1:
            if lower[k - 1] > best[2]:
                break
            sd, ud = self.probe(int(k)).face_distance(p[0])
            if math.isnan(ud):
                return 0, math.nan, math.nan
            if ud < best[2]:
                best = (int(k), sd, ud)
        return best if best[0] else (0, math.nan, math.nan)


class Material:
    """Which points of space lie in the part's material (``IN``, ``OUT`` or ``ON``).

    ``kind`` is ``SOLID`` when the part has solids (OCCT's solid classifier, one per solid,
    with the boundary tolerance ``tol.classify``), else ``FACES`` (the material side of
    the nearest face). ``solids``: the TopoDS solids to use (default every solid of the
    part's shape; ``[]`` forces the faces' rule). ``classified`` counts the classifier
    calls.
    """

    def __init__(self, faces: PartFaces, tol: Tolerances, solids=None):
        self.faces, self.tol = faces, tol
        model = getattr(faces.part, "surface_model", None)
        if solids is None and model is not None and not model.closed:
            solids = []  # an open shell bounds no volume: the faces' sides decide
        self.flipped = bool(getattr(faces.part, "flip_material", False))
        if solids is None:  # every solid of the part's shape
            solids = []
            explorer = TopExp_Explorer(faces.part.shape, TopAbs_SOLID)
            while explorer.More():
                solids.append(TopoDS.Solid_s(explorer.Current()))
                explorer.Next()
        self.solids = list(solids)
        self.kind = SOLID if self.solids else FACES
        self._boxes = [_box(s, optimal=False) for s in self.solids]
        self._classifiers: list = [None] * len(self.solids)
        self.classified = 0

    def state(self, point) -> str | None:
        """IN, OUT or ON; None when it cannot be told (the caller fails closed)."""
        if self.kind == FACES:
            return self.side_of_nearest_face(point)
        p = np.asarray(point, float)
        on = unknown = False
        for k, solid in enumerate(self.solids):
            lo, hi = self._boxes[k]
            if np.any(p < lo - BOX_MARGIN) or np.any(p > hi + BOX_MARGIN):
                continue  # outside this solid's box: outside this solid
            if self._classifiers[k] is None:
                self._classifiers[k] = BRepClass3d_SolidClassifier(solid)
            classifier = self._classifiers[k]
            classifier.Perform(gp_Pnt(*map(float, p)), self.tol.classify)
            self.classified += 1
            state = classifier.State()
            if state == TopAbs_IN:
                return OUT if self.flipped else IN
            on |= state == TopAbs_ON
            unknown |= state not in (TopAbs_IN, TopAbs_ON, TopAbs_OUT)
        if on:
            return ON
        if unknown:  # the classifier could not tell: the faces' sides decide
            return self.side_of_nearest_face(point)
        return IN if self.flipped else OUT

    def side_of_nearest_face(self, point) -> str | None:
        """The faces' rule: IN when the point lies on the material side of the nearest
        face (the face's normals already carry the chosen side, flipped or not).

        Where the nearest point q lies inside the face, its normal there decides. Where it
        lies on the face's boundary (an edge or a vertex), the faces within :data:`TIE` of
        the same distance share q, and the sum of their normals at q decides (a
        pseudo-normal: exact for an edge between two faces, concave or convex; at a free
        edge of an open shell the one face's normal, as if the sheet went on; at a vertex
        of three or more faces an unweighted sum, which can err: docs/notes/surface_models.md).
        """
        face, signed, unsigned = self.faces.nearest(point)
        if not face or math.isnan(signed):
            return None
        if unsigned <= self.tol.noise:
            return ON
        if signed < 0:
            return IN
        if not self._on_boundary(face):  # inside the face, on its outer side
            return OUT
        side = self._pseudo_normal_side(np.asarray(point, float), face, unsigned)
        if side is None:
            return None
        return IN if side < 0 else OUT

    def _on_boundary(self, face: int) -> bool:
        """Whether the last distance to ``face`` found its foot on the face's boundary."""
        dss = self.faces.probe(face)._dss  # the probe's last DistShapeShape (face_distance)
        return any(dss.SupportTypeShape2(k) != BRepExtrema_IsInFace
                   for k in range(1, dss.NbSolution() + 1))

    def _pseudo_normal_side(self, p: np.ndarray, face: int, d: float) -> float | None:
        """(p - q) . (sum of the normals at q of the faces at distance d from p), or None."""
        q = np.array(self.faces.probe(face)._dss.PointOnShape2(1).Coord())
        total = np.zeros(3)
        for k in self.faces.near(p - d - TIE, p + d + TIE, 0.0):
            probe = self.faces.probe(k)
            _, ud = probe.face_distance(p)
            if not abs(ud - d) <= TIE:
                continue
            found = probe.project_global(q)
            if found is None:
                return None
            total += probe.normal(*found[:2])
        return float((p - q) @ total)
