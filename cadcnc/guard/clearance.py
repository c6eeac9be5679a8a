"""How far the ball and its shank are from the rest of the part: the third-face guard.

For a pair of faces (i, j) followed by a ball of offset R' on a shank of radius R' and
length L along +Z, :meth:`ClearanceGuard.margin` answers, for a ball centre p (mm), the
signed clearance (mm) of the tool from the part: >= 0 clear, < 0 a hit, with a detail
naming the face and whether the ball or the shank touches it.

- Third faces (every face but i and j): the tool is the capsule half "ball at p, shank
  up to p + L z", i.e. every point within R' of the segment p .. p + L z. Its clearance
  from face K is dist(segment, K) - (R' - tol). The nearest point of the segment says
  who touches: p itself (the ball) or a point above it (the shank).
- The pair's own faces i and j touch the ball by construction (distance R', up to the
  path's own error), so an absolute rule would fire on path noise. Their rule is
  relative: the shank must come no nearer to face i than the ball is, minus tol:
  dist(segment, i) - (dist(p, i) - tol). This is exact for a vertical wall (the shank
  is tangent along it: margin tol) and catches an overhanging own face. It is skipped in
  closed form for a plane whose outward normal has n_z >= 0 and for a cylinder with a
  vertical axis (there the segment is never nearer than its foot).
- Distances are unsigned (OCCT's BRepExtrema_DistShapeShape): along a valid path the
  centre lies outside the part, on the cutter side of faces i and j, so a face within
  reach is a hit whichever side the centre is on. The whole-part gouge gate stays the
  final, material-aware check of every written path.

Cost: a broad phase on the faces' boxes (re-done only after the centre has moved by
``reach``), then a Lipschitz cache per face (a distance d measured at p0 bounds the
distance at p from below by d - |p - p0|; the own-face margin is 2-Lipschitz), so exact
OCCT distances are computed only for faces that may be within R' of the tool. The
returned margin is exact when some face needs it (in particular whenever it is < 0
or near 0), otherwise a positive lower bound.
"""

from __future__ import annotations

import math

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Builder
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape, BRepExtrema_IsInFace
from OCP.gp import gp_Pnt
from OCP.TopAbs import TopAbs_EDGE, TopAbs_VERTEX
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS_Compound
from OCP.TopTools import TopTools_IndexedMapOfShape

from ..core.tolerances import DEFAULT, VERTICAL
from .analytic_faces import AnalyticFace
from .face_distance import FaceDistance

TIE = 1e-9  # mm: margins this close are the same contact
BOX_SLACK = 1e-4  # mm added to each face box: OCCT's optimal box is tight, not outer-exact


OWN_SLOPE = 2.0
"""The own-face margin's Lipschitz constant in the centre (mm per mm): the segment's
distance less the ball's, each 1-Lipschitz."""
SECOND_OPINION = 1e-7
"""mm: a torus's second opinion replaces OCCT's segment distance only when nearer by more
than OCCT's precision (where OCCT is right they agree, and nothing changes)."""


class ClearanceGuard:
    """The clearance of ball + shank from a part, for the pair of faces ``pair``.

    ``pair`` may also be one face (a 1-tuple: the face a finishing pass follows on a guide
    plane); every other face of the part is then a third face.

    ``offset`` R' (mm), ``shank`` L (mm, 0 for a ball alone), ``tol`` (mm, the 1 µm of
    the spec: a face nearer than R' - tol is a hit). ``reach`` (mm) is the broad phase's
    radius: faces whose box is further than R' + reach from the tool are not looked at
    again until the centre has moved by ``reach``.
    """

    def __init__(self, part, pair: tuple[int, ...], offset: float, shank: float,
                 tol: float = DEFAULT.hit, reach: float | None = None,
                 own_tol: float = DEFAULT.gouge):
        self.part = part
        self.pair = tuple(int(k) for k in pair)   # two faces, or one (a finishing pass)
        self.offset = float(offset)
        self.shank = float(shank)
        self.tol = float(tol)
        self.threshold = self.offset - self.tol   # mm: nearer than this is a hit
        # the ball against its own faces' edges: the spec's 1 um (the path touches its own
        # faces at R' up to its own error, so the third faces' 1 nm would fire on noise)
        self.own_threshold = self.offset - float(own_tol)
        self.reach = max(self.offset, 1.0) if reach is None else float(reach)
        self._faces, self._analytic, self._lo, self._hi = _part_data(part)
        self._own_shapes = TopTools_IndexedMapOfShape()   # edges and vertices of i and j
        for k in self.pair:
            for kind in (TopAbs_EDGE, TopAbs_VERTEX):
                TopExp.MapShapes_s(self._faces[k - 1].topods, kind, self._own_shapes)
        self._own_rule = {k: _needs_own_rule(self._faces[k - 1]) for k in self.pair}
        self._edges: dict = {}              # face -> compound of its free edges (planes)
        self._own_edges: dict = {}          # own face -> compound of all its edges
        self._edge_bound: dict = {}         # own face -> (p0, distance to its edges at p0)
        self._pieces: dict = {}             # face -> its FaceDistance (OCCT's pieces)
        self._broad_at: tuple[float, float, float] | None = None
        self._near: list[int] = []          # face numbers within reach at _broad_at
        self._bound: dict[int, tuple] = {}  # face -> (p0, lower bound of the margin at p0, slope)
        self._hits: dict[int, tuple] = {}   # third face -> (p0, its exact margin < 0 at p0, who)
        self._shared: dict[int, tuple] = {}  # third face -> boxes of what it shares with i, j
        self.calls = 0
        self.exact_calls = 0     # OCCT distances
        self.closed_calls = 0    # closed-form distances
        self.broad_calls = 0
        self.proven_calls = 0    # answers proven without a distance

    # -- the guard ------------------------------------------------------------------------
    def margin(self, p) -> tuple[float, str]:
        """(clearance mm, detail) of the tool with its ball centre at ``p`` (3 floats).

        >= 0: clear ("" or the nearest face's name); < 0: a hit, with the detail
        "ball touches face K" or "shank touches face K".
        """
        return self._margin(p, False)[:2]

    def first_hit(self, p) -> tuple[float, str, bool]:
        """:meth:`margin`, or as soon as one face is found cutting in (the faces taken
        from the lowest bound up): (clearance or, on such a hit, the hit face's exact
        margin, an upper bound of the clearance, mm; detail; whether it is the exact
        clearance). For a verdict that needs only the sign."""
        return self._margin(p, True)[:3]

    def clears(self, p) -> bool:
        """Whether the tool at ``p`` clears the part (``margin(p) >= 0``), stopping at the
        first face found to hit: for a yes or no that needs no least margin nor its face
        (the setups' reach samples)."""
        return self._margin(p, True)[0] >= 0.0

    def clear_along(self, points) -> list[bool]:
        """Whether the tool clears the part at each of ``points`` ((m, 3) mm, in order
        along a run: a free run past a collision), as ``margin(p)[0] >= 0`` says, measured
        only where no hit measured before decides: an own face's margin is 2-Lipschitz in
        the centre (the segment's distance less the ball's), so a hit m0 < 0 on it at p0
        is still one at p while m0 + 2 |p - p0| < 0; on an own torus face a point of the
        shank proves one (:meth:`_torus_hit`); a third face's hits go through
        :meth:`proven_hit` (its shared edges can clear it)."""
        out = []
        own_hit = None   # (p0, m0) of the last own face's measured hit
        for q in points:
            p = (float(q[0]), float(q[1]), float(q[2]))
            if own_hit is not None and \
                    own_hit[1] + OWN_SLOPE * distance(p, own_hit[0]) < 0.0:
                self.proven_calls += 1
                out.append(False)
                continue
            if (self._hits and self.proven_hit(p) is not None) or self._torus_hit(p):
                self.proven_calls += 1
                out.append(False)
                continue
            m, _, _, face = self._margin(p, False)
            own_hit = (p, m) if m < 0.0 and face in self.pair else None
            out.append(m >= 0.0)
        return out

    def _torus_hit(self, p) -> bool:
        """Whether an own torus face proves a hit at ``p`` without OCCT's segment distance:
        the face's distance at the shank's point nearest the whole torus (an upper bound
        of the shank's distance) is below the ball's less tol."""
        for k in self.pair:
            a = self._analytic[k - 1]
            if a.kind != "torus" or not self._own_rule[k] or \
                    self._hi[k - 1][2] - BOX_SLACK <= p[2]:   # (the face below: clear)
                continue
            s = a.segment_nearest(p, self.shank)
            if s is None:
                continue
            d_q = self._point_distance(k, (p[0], p[1], p[2] + s))
            d_p = self._point_distance(k, p)
            if d_q - (d_p - self.tol) < 0.0:   # (-inf, unknown: a hit, failing closed)
                return True
        return False

    def _margin(self, p, stop: bool) -> tuple[float, str, bool, int | None]:
        """:meth:`margin`, stopping at the first hit when ``stop`` (:meth:`first_hit`),
        and the face of the margin (None: no face within reach)."""
        self.calls += 1
        p = (float(p[0]), float(p[1]), float(p[2]))
        if not math.isfinite(p[0] + p[1] + p[2]):
            return -math.inf, "ball centre is not a finite point", True, None  # fail closed
        moved = math.inf if self._broad_at is None else distance(p, self._broad_at)
        if moved > self.reach:
            self._broad_phase(p)
            moved = 0.0
        best, detail, face = self.reach - moved, "", None   # the faces not near: reach left
        bounds = [(self._bound[k][1] - self._bound[k][2] * distance(p, self._bound[k][0]), k)
                  for k in self._near]
        for m, k in sorted(bounds) if stop else bounds:
            who = ""
            if m < 0.0:    # the bound cannot clear it: measure
                m, who = self._exact(k, p)
            # on a tie (a wall and its rim at once) name the ball: it is what the user sees
            if m < best - TIE or (m < best + TIE and who == "ball"):
                best, face = m, k
                detail = f"{who} touches face {k}" if m < 0.0 else \
                    (f"{who} nearest face {k}" if who else f"face {k} within reach")
            if stop and best < 0.0:
                return best, detail, False, face
        return best, detail, True, face

    def _broad_phase(self, p) -> None:
        """Faces whose box may come within R' of the tool before the centre moves
        ``reach``: box-to-box distance of the tool's segment box and each face box."""
        self.broad_calls += 1
        seg_lo = np.array(p)
        seg_hi = seg_lo + (0.0, 0.0, self.shank)
        gap = np.maximum(np.maximum(self._lo - seg_hi, seg_lo - self._hi), 0.0)
        box_dist = np.sqrt((gap * gap).sum(axis=1))                     # (n,)
        near = np.nonzero(box_dist < self.threshold + self.reach)[0] + 1
        self._broad_at = p
        self._near = []
        for k in near.tolist():
            if k in self.pair:
                if not self._own_rule[k]:
                    continue
                self._bound.setdefault(k, (p, -1.0, 2.0))
            elif k not in self._bound:
                self._bound[k] = (p, float(box_dist[k - 1]) - self.threshold, 1.0)
            self._near.append(k)

    def _exact(self, k: int, p) -> tuple[float, str]:
        """The exact margin of face k at p (OCCT distances) and who is nearest; cached.

        A face lying wholly below the centre (its box's top at or under p_z) is nearest
        to the segment at p itself (|p + s z - q| >= |p - q| for q_z <= p_z, s >= 0):
        the ball decides, and one point distance is enough; for the pair's own faces it
        cannot come nearer to the shank than to the ball (margin tol).
        A third face met only on an edge or vertex it shares with face i or j is met
        where the pair's own face is (a wall's top edge beside a shank tangent to the
        wall): that contact belongs to the own face's rule, and counts as clear.
        """
        below = self._hi[k - 1][2] - BOX_SLACK <= p[2]
        own = k in self.pair
        if own:
            if below:
                m = self.tol
            else:
                m = self._own_bound(k, p)
                if m is None or m < 0.0:
                    d_p = self._point_distance(k, p)
                    d_seg = self._segment_distance(k, p, None, d_p)[0]   # cap: d_p
                    # an unknown distance fails closed (-inf is a hit, never an inf margin)
                    m = d_seg - (d_p - self.tol) if math.isfinite(d_seg + d_p) else -math.inf
            m_edge = self._own_edge_margin(k, p)
            if m_edge < min(m, 0.0):   # the ball cuts the own face's boundary
                self._bound[k] = (p, m_edge, 2.0)
                return m_edge, "ball"
        else:
            d, own_edge = self._segment_distance(k, p, 0.0 if below else self.shank)
            m = d - self.threshold
            if own_edge:
                m = max(m, 0.0)
        self._bound[k] = (p, m, 2.0 if own else 1.0)
        if own or m >= 0.0:
            return m, "shank" if own else "tool"
        who = "ball" if below or self._point_distance(k, p) < self.threshold else "shank"
        if math.isfinite(m):   # (-inf: an unknown distance, measured again)
            self._hits[k] = (p, m, who)
        return m, who

    def proven_hit(self, p) -> tuple[float, str] | None:
        """(an upper bound < 0 of the clearance at ``p`` (mm), detail) when a hit measured
        nearby proves one without OCCT, else None. A third face's margin is 1-Lipschitz
        in the centre (the distance from the tool's segment, which moves with it): a
        margin m0 < 0 measured at p0 leaves at most m = m0 + |p - p0| at p. A contact met
        only on an edge or vertex the face shares with face i or j counts as clear, so
        for a face that shares any, the boxes of those edges and vertices must also lie
        further than R' - tol + m from the segment (then no nearest point is on them).
        The detail names the face and who touched it at p0."""
        p = (float(p[0]), float(p[1]), float(p[2]))
        best = None
        for k, (p0, m0, who) in self._hits.items():
            m = m0 + distance(p, p0)
            if m < 0.0 and (best is None or m < best[0]) and \
                    self._shared_distance(k, p) > self.threshold + m:
                best = (m, f"{who} touches face {k}")
        return best

    def _shared_distance(self, k: int, p) -> float:
        """A lower bound (mm) of the distance from the tool's segment at ``p`` to the edges
        and vertices face k shares with face i or j (their boxes'; inf: none shared)."""
        if k not in self._shared:
            self._shared[k] = _shared_boxes(self._faces[k - 1].topods, self._own_shapes)
        lo, hi = self._shared[k]
        if not len(lo):
            return math.inf
        seg_lo = np.array(p)
        seg_hi = seg_lo + (0.0, 0.0, self.shank)
        gap = np.maximum(np.maximum(lo - seg_hi, seg_lo - hi), 0.0)
        return float(np.sqrt((gap * gap).sum(axis=1)).min())

    def _segment_distance(self, k: int, p, length: float | None = None,
                          cap: float | None = None) -> tuple[float, bool]:
        """(distance mm from the segment p .. p + length z (default L) to face k, whether
        every nearest point of the face lies on an edge or vertex of face i or j): in
        closed form for an analytic face whose foot is inside it (then not on an edge);
        for a third face whose distance to its whole surface already clears R' - tol, that
        distance (a lower bound: the margin stays >= 0); else OCCT's, of the segment
        clipped to the face box's heights widened by ``cap`` (default R' + reach: a
        larger distance is only ever compared with R' - tol, or cached for moves shorter
        than reach, after which the broad phase runs again): a point of
        the segment further than ``cap`` above or below the box is further than ``cap``
        (its box distance, ``cut``) from the face, so the distance is exact when it is at
        most ``cut``, and ``cut`` (a lower bound) otherwise. The own-face rule passes cap =
        d(p, face), which the segment's own foot p reaches: exact there."""
        length = self.shank if length is None else length
        d = self._closed_segment_distance(k, p, length)
        if d is not None:
            return d, False
        cap = self.offset + self.reach if cap is None else cap
        lo, hi = self._lo[k - 1], self._hi[k - 1]
        z0, z1 = max(p[2], lo[2] - cap), min(p[2] + length, hi[2] + cap)
        # the part cut off is at least cap from the box's heights: its box distance
        cut = math.hypot(cap, math.hypot(max(lo[0] - p[0], p[0] - hi[0], 0.0),
                                         max(lo[1] - p[1], p[1] - hi[1], 0.0))) \
            if z0 > p[2] or z1 < p[2] + length else math.inf
        if z1 < z0:   # the whole segment is further than cap from the face
            return cut, False
        self.exact_calls += 1
        face = self._faces[k - 1].topods
        if self._analytic[k - 1].kind == "plane" and k not in self.pair:
            # the distance to a segment is convex on the plane: with the foot outside the
            # face the nearest point is on the face's boundary; a contact on an edge of
            # face i or j counts as clear (the own face's rule), so only the others count
            face = self._free_edges(k)
            if face is None:
                return math.inf, False
        elif self._analytic[k - 1].kind in (None, "torus"):
            # no closed forms (a B-spline): OCCT's pieces, its edges only where they can win
            # (guard/face_distance.py; on r0901_ec's cylinders they rarely prune); a torus:
            # its interior in closed form (OCCT's extrema can miss it), its edges so
            if k not in self._pieces:
                a = self._analytic[k - 1]
                self._pieces[k] = FaceDistance(face, self._own_shapes,
                                               a if a.kind == "torus" else None)
            pieces = self._pieces[k]
            got = pieces.distance(p, z0, z1) if pieces.useful else None
            if got is not None:
                return (cut, False) if got[0] > cut else got
        a = gp_Pnt(p[0], p[1], z0)
        shape = BRepBuilderAPI_MakeEdge(a, gp_Pnt(p[0], p[1], z1)).Edge() \
            if z1 > z0 else BRepBuilderAPI_MakeVertex(a).Vertex()
        ext = BRepExtrema_DistShapeShape(shape, face)
        if not ext.IsDone() or ext.NbSolution() == 0:
            return -math.inf, False  # fail closed: an unknown distance is a hit
        second = self._torus_second_opinion(k, p, z0, z1, ext.Value())
        if second < ext.Value() - SECOND_OPINION:   # OCCT missed the nearer part
            return min(second, cut), False
        if ext.Value() > cut:
            return cut, False
        own = all(ext.SupportTypeShape2(n) != BRepExtrema_IsInFace
                  and self._own_shapes.Contains(ext.SupportOnShape2(n))
                  for n in range(1, ext.NbSolution() + 1))
        return ext.Value(), own

    def _torus_second_opinion(self, k: int, p, z0: float, z1: float, occt: float) -> float:
        """On a torus face, the face's distance (mm) at the point of the segment (p_x,
        p_y) x [z0, z1] nearest the whole torus (closed form): an upper bound of the
        segment's distance that OCCT's curve-to-surface extrema can miss (it proposed one
        extremum, on the seam, for bug28414's torus: docs/notes/guard-calls.md); inf on
        other faces, or where the whole torus comes no nearer there than ``occt`` (the
        face, a part of it, cannot either: no distance asked)."""
        a = self._analytic[k - 1]
        if a.kind != "torus":
            return math.inf
        s = a.segment_nearest((p[0], p[1], z0), z1 - z0)
        if s is None:
            return math.inf
        q = (p[0], p[1], z0 + s)
        whole = a.point_distance(q, trimmed=False)   # None: no unique foot there
        if whole is not None and whole >= occt - SECOND_OPINION:
            return math.inf
        return self._point_distance(k, q)

    def _closed_segment_distance(self, k: int, p, length: float) -> float | None:
        """The closed forms of :meth:`_segment_distance` (mm), or None when none applies."""
        a = self._analytic[k - 1]
        if a.kind is None:
            return None
        d = a.segment_distance(p, length)
        if d is None and k not in self.pair:
            d = a.segment_distance(p, length, trimmed=False)
            d = d if d is not None and d >= self.threshold else None
        if d is not None:
            self.closed_calls += 1
        return d

    def _own_edge_margin(self, k: int, p) -> float:
        """The ball's margin (mm, against R' - own_tol) from the edges of own face k: the
        ball touches face k at R' at its foot by construction, but near the face's boundary the nearest point of the
        trimmed face can be an edge nearer than the foot (a B-spline face curving towards
        the ball past a convex edge, where the ball would cut the face beyond the gouge
        limit). Lipschitz-cached apart from the face's own bound (slope 1)."""
        p0, d0 = self._edge_bound.get(k, (None, None))
        if p0 is not None and d0 - distance(p, p0) - self.own_threshold >= 0.0:
            return d0 - distance(p, p0) - self.own_threshold
        if k not in self._own_edges:
            edges = TopTools_IndexedMapOfShape()
            TopExp.MapShapes_s(self._faces[k - 1].topods, TopAbs_EDGE, edges)
            comp, builder = TopoDS_Compound(), BRep_Builder()
            builder.MakeCompound(comp)
            for e in range(1, edges.Extent() + 1):
                builder.Add(comp, edges.FindKey(e))
            self._own_edges[k] = comp
        self.exact_calls += 1
        ext = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(*p)).Vertex(),
                                         self._own_edges[k])
        d = ext.Value() if ext.IsDone() and ext.NbSolution() else -math.inf
        self._edge_bound[k] = (p, d)
        return d - self.own_threshold

    def _own_bound(self, k: int, p) -> float | None:
        """A lower bound of own face k's margin in closed form (a torus: the segment's
        distance to the whole torus, the ball's to the face), or None."""
        a = self._analytic[k - 1]
        lb = a.segment_lower_bound(p, self.shank)
        d_p = a.point_distance(p) if lb is not None else None
        if d_p is None:
            return None
        self.closed_calls += 1
        return lb - (d_p - self.tol)

    def _free_edges(self, k: int):
        """A compound of face k's edges that face i and j do not share, or None."""
        if k not in self._edges:
            edges = TopTools_IndexedMapOfShape()
            TopExp.MapShapes_s(self._faces[k - 1].topods, TopAbs_EDGE, edges)
            comp, builder, n = TopoDS_Compound(), BRep_Builder(), 0
            builder.MakeCompound(comp)
            for e in range(1, edges.Extent() + 1):
                if not self._own_shapes.Contains(edges.FindKey(e)):
                    builder.Add(comp, edges.FindKey(e))
                    n += 1
            self._edges[k] = comp if n else None
        return self._edges[k]

    def _point_distance(self, k: int, p) -> float:
        """Distance (mm) from p to face k: closed form where it applies, else OCCT's."""
        d = self._analytic[k - 1].point_distance(p)
        if d is not None:
            self.closed_calls += 1
            return d
        self.exact_calls += 1
        face = self._faces[k - 1].topods
        ext = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(*p)).Vertex(), face)
        return ext.Value() if ext.IsDone() and ext.NbSolution() else -math.inf


def _shared_boxes(face, own_shapes) -> tuple[np.ndarray, np.ndarray]:
    """(lows (m, 3), highs (m, 3)): the boxes (exact geometry, widened by BOX_SLACK mm) of
    the edges and vertices of ``face`` that ``own_shapes`` holds."""
    boxes = []
    for kind in (TopAbs_EDGE, TopAbs_VERTEX):
        shapes = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(face, kind, shapes)
        for n in range(1, shapes.Extent() + 1):
            if own_shapes.Contains(shapes.FindKey(n)):
                box = Bnd_Box()
                BRepBndLib.AddOptimal_s(shapes.FindKey(n), box, False, False)
                boxes.append(box.Get())
    b = np.array(boxes, dtype=float).reshape(-1, 6)
    return b[:, :3] - BOX_SLACK, b[:, 3:] + BOX_SLACK


def _part_data(part) -> tuple:
    """(faces, closed forms, box lows (n, 3), box highs (n, 3)) of every face of a part,
    computed once per part, kept on it and shared by its guards (optimal boxes cost about
    4 ms a face, seconds on a part of hundreds of faces, and pencil builds a guard per
    pair)."""
    data = part.derived.get(__name__)
    if data is None:
        faces = [part.face(k) for k in range(1, len(part) + 1)]
        analytic = [AnalyticFace(f) for f in faces]   # closed forms, or kind None
        lo, hi = part.face_boxes()   # shared with the part's own box
        data = (faces, analytic, lo - BOX_SLACK, hi + BOX_SLACK)
        part.derived[__name__] = data
    return data


def face_boxes(part) -> tuple[np.ndarray, np.ndarray]:
    """(lows (n, 3), highs (n, 3)) of every face's optimal box, widened by BOX_SLACK mm:
    the boxes every guard of the part shares (computed once per part)."""
    _, _, lo, hi = _part_data(part)
    return lo, hi


def _needs_own_rule(face) -> bool:
    """False where a shank above the ball can never come nearer to this face than the
    ball's own contact: a plane whose outward normal has n_z >= 0, or a cylinder whose
    axis is vertical, or a surface of extrusion along Z (all three in closed form: the
    horizontal distance from any point of the vertical segment is the ball's)."""
    surf = face._adaptor
    if face.kind == "plane":
        u, w = np.mean(face.u_range), np.mean(face.w_range)
        return face.normal(u, w)[2] < -1e-12   # faces down beyond a unit normal's round-off
    if face.kind == "cylinder":
        axis = surf.Cylinder().Axis().Direction()
        return abs(abs(axis.Z()) - 1.0) > VERTICAL
    if face.kind == "extrusion":
        return abs(abs(surf.Direction().Z()) - 1.0) > VERTICAL
    return True


def distance(a, b) -> float:
    return math.sqrt((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2)
