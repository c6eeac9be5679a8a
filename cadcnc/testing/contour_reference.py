"""The true contour error of sampled positions, against references that share nothing
with the kernel (issue 35, item 3).

Each piece of a plan (``stream.plan.pieces``: a cut's points, or a link's straight move)
gets its own exact path, never a chord across a join:

- a link, or a cut whose points are collinear (within ``FIT_TOL``): the segment, closed form;
- a cut whose points lie on a circle (plane, centre and radius fitted from the points,
  residual within ``FIT_TOL``): the arc, closed form;
- any other cut (a corner path between two faces): the two offset surfaces, by OCCT
  (``BRepExtrema_DistShapeShape`` through ``cadcnc.verification.probe.FaceProbe``): for a
  point p, max(|dist(p, face_a) - R_a|, |dist(p, face_b) - R_b|); beyond the cut's first
  or last point, at least the distance to that point;
- a finishing pass on a free-form face (one face, its points in a plane): the face's
  offset surface by OCCT and the guide plane, max(|dist(p, face) - R|, |plane distance|).

Positions (K, 3) mm; distances (K,) mm. ``stream_error`` measures each stream row against
its own piece; ``distance`` measures a sample against the nearest piece (LinuxCNC's runs,
whose samples belong to no piece).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from cadcnc.verification.probe import FaceProbe

FIT_TOL = 1e-9      # mm: the largest residual of a line or circle fitted to a cut's points
NEAR = 0.01         # mm: pieces whose polyline is this close to the nearest are measured


def _segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(K,) distance of points p (K, 3) to the segment a-b (mm)."""
    ab = b - a
    t = np.clip(((p - a) @ ab) / max(float(ab @ ab), 1e-300), 0.0, 1.0)  # no / 0
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)


class Line:
    """The segment from the first to the last point."""

    kind = "line"

    def __init__(self, a: np.ndarray, b: np.ndarray):
        self.a, self.b = np.asarray(a, float), np.asarray(b, float)

    def distance(self, p: np.ndarray) -> np.ndarray:
        return _segment(np.atleast_2d(p), self.a, self.b)


class Arc:
    """A circular arc: centre c, unit normal n, radius r, from angle 0 (unit e1) to
    ``span`` rad about n (e2 = n x e1)."""

    kind = "arc"

    def __init__(self, c, n, r, e1, span, ends):
        self.c, self.n, self.r, self.e1, self.span = c, n, r, e1, span
        self.e2 = np.cross(n, e1)
        self.ends = ends

    def distance(self, p: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(p) - self.c
        z = q @ self.n
        x, y = q @ self.e1, q @ self.e2
        rho = np.hypot(x, y)
        ang = np.mod(np.arctan2(y, x), 2 * np.pi)
        on = (ang <= self.span) | (rho == 0)
        d_arc = np.hypot(z, rho - self.r)
        d_end = np.minimum(np.linalg.norm(q + self.c - self.ends[0], axis=1),
                           np.linalg.norm(q + self.c - self.ends[1], axis=1))
        return np.where(on, d_arc, d_end)


def fit_line(pts: np.ndarray) -> Line | None:
    """The segment through the first and last point, if every point is within FIT_TOL."""
    line = Line(pts[0], pts[-1])
    return line if len(pts) < 3 or line.distance(pts).max() <= FIT_TOL else None


def fit_arc(pts: np.ndarray) -> Arc | None:
    """The arc through the points (plane by SVD, circle by least squares), if every point
    is within FIT_TOL of it; the points must turn one way by less than a full turn."""
    if len(pts) < 4:
        return None
    o = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - o)
    n = vt[2]
    if np.abs((pts - o) @ n).max() > FIT_TOL:
        return None
    u, v = vt[0], vt[1]
    x, y = (pts - o) @ u, (pts - o) @ v
    A = np.c_[2 * x, 2 * y, np.ones_like(x)]
    (cx, cy, _), *_ = np.linalg.lstsq(A, x * x + y * y, rcond=None)
    for _ in range(5):   # Gauss-Newton on the geometric residual |p - c| - r
        dx, dy = x - cx, y - cy
        rho = np.hypot(dx, dy)
        r = rho.mean()
        J = np.c_[-dx / rho, -dy / rho]
        step, *_ = np.linalg.lstsq(J - J.mean(axis=0), -(rho - r), rcond=None)
        cx, cy = cx + step[0], cy + step[1]
    c = o + cx * u + cy * v
    r = float(np.hypot(x - cx, y - cy).mean())
    e1 = (pts[0] - c) - ((pts[0] - c) @ n) * n
    e1 /= np.linalg.norm(e1)
    if np.cross(e1, pts[len(pts) // 2] - c) @ n < 0:
        n = -n
    arc = Arc(c, n, r, e1, 0.0, (pts[0], pts[-1]))
    ang = np.unwrap(np.arctan2((pts - c) @ arc.e2, (pts - c) @ arc.e1))
    if np.any(np.diff(ang) < -1e-12) or ang[-1] >= 2 * np.pi:   # rad: round-off
        return None
    arc.span = float(ang[-1])
    d = np.hypot((pts - c) @ n, np.linalg.norm(np.cross(pts - c, n), axis=1) - r)
    return arc if d.max() <= FIT_TOL else None


class Offsets:
    """A corner path: the two faces' offset surfaces at R_a, R_b (OCCT distances), and
    the cut's end points (beyond them, the distance to the nearer end)."""

    kind = "offsets"

    def __init__(self, faces, radii, pts: np.ndarray):
        self.probes = [FaceProbe(f) for f in faces]
        self.radii = radii
        self.pts = pts
        self._tree = cKDTree(pts)
        self.h = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).max())

    def feet(self, q: np.ndarray) -> list[tuple[float, np.ndarray]]:
        """Per face: (distance mm, nearest point (3,)) of one point q (3,)."""
        out = []
        for pr in self.probes:
            d = pr.face_distance(q)[1]
            out.append((d, np.array(pr._dss.PointOnShape2(1).Coord())))
        return out

    def on_path(self, q: np.ndarray, steps: int = 6) -> np.ndarray:
        """A point on both offset surfaces near q (3,) (Newton in the span of the two
        normals): points known on the path, to check the reference itself."""
        q = np.asarray(q, float).copy()
        for _ in range(steps):
            (da, fa), (db, fb) = self.feet(q)
            na, nb = (q - fa) / da, (q - fb) / db
            N = np.vstack([na, nb])
            rhs = -np.array([da - self.radii[0], db - self.radii[1]])
            q = q + N.T @ np.linalg.solve(N @ N.T, rhs)
        return q

    def distance(self, p: np.ndarray) -> np.ndarray:
        p = np.atleast_2d(p)
        out = np.zeros(len(p))
        for i, q in enumerate(p):
            out[i] = max(abs(pr.face_distance(q)[1] - r)
                         for pr, r in zip(self.probes, self.radii))
        # past an end (its foot on the polyline would lie beyond it): that end's distance;
        # a closed corner path (a loop: first point = last) has no end to pass
        closed = np.linalg.norm(self.pts[0] - self.pts[-1]) <= 1e-6   # mm: Tolerances.closed
        last = len(self.pts) - 1
        ends = () if closed else ((0, 1), (last, last - 1))
        for at, nxt in ends:   # its foot beyond this end: the nearest point is this end
            end = self.pts[at]
            past = (p - end) @ (end - self.pts[nxt]) > 0
            _, k = self._tree.query(p[past])
            sel = np.flatnonzero(past)[k == at]
            out[sel] = np.maximum(out[sel], np.linalg.norm(p[sel] - end, axis=1))
        return out


class Guided(Offsets):
    """A finishing pass: the face's offset surface at R (OCCT distance) and the guide
    plane the pass lies in (fitted to the cut's points, residual within ``FIT_TOL``, as
    an arc's plane is): max(|dist(p, face) - R|, |(p - o) . n|); past an end, at least
    the distance to it (as :class:`Offsets`)."""

    kind = "guided"

    def __init__(self, face, radius: float, pts: np.ndarray, o: np.ndarray, n: np.ndarray):
        super().__init__([face], (radius,), pts)
        self.o, self.n = o, n

    def distance(self, p: np.ndarray) -> np.ndarray:
        p = np.atleast_2d(p)
        return np.maximum(super().distance(p), np.abs((p - self.o) @ self.n))

    def on_path(self, q: np.ndarray, steps: int = 6) -> np.ndarray:
        """A point on the offset surface and the plane near q (3,): Newton in the span of
        the face's normal and the plane's (points known on the path, to check it)."""
        q = np.asarray(q, float).copy()
        for _ in range(steps):
            ((d, f),) = self.feet(q)
            N = np.vstack([(q - f) / d, self.n])
            rhs = -np.array([d - self.radii[0], (q - self.o) @ self.n])
            q = q + N.T @ np.linalg.solve(N @ N.T, rhs)
        return q


def fit_plane(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(a point, unit normal) of the plane through the points, if every point is within
    FIT_TOL of it (and they span one: not a line)."""
    if len(pts) < 3:
        return None
    o = pts.mean(axis=0)
    _, sv, vt = np.linalg.svd(pts - o, full_matrices=False)
    if sv[1] <= FIT_TOL * len(pts) or np.abs((pts - o) @ vt[2]).max() > FIT_TOL:
        return None
    return o, vt[2]


def piece_reference(piece, program, part):
    """The exact path of one piece: Line, Arc or Offsets (see the module doc)."""
    pts = np.asarray(piece.points, float)
    if piece.cut is None or len(pts) < 3:
        return Line(pts[0], pts[-1])
    ref = fit_line(pts) or fit_arc(pts)
    if ref is not None:
        return ref
    path = program.cuts[piece.cut].path
    fa, fb = path.faces
    plane = fit_plane(pts) if fa is not None and fb is None else None
    if plane is not None:   # a finishing pass: one face on a guide plane
        return Guided(part.face(fa).topods, path.offsets[0], pts, *plane)
    if fa is None or fb is None:
        raise ValueError(f"cut {piece.cut}: neither a line nor an arc, and not between "
                         f"two faces of the part (faces {path.faces})")
    return Offsets([part.face(fa).topods, part.face(fb).topods], path.offsets, pts)


class PathReference:
    """The exact path of every piece of a plan (``pieces``: ``stream.plan.pieces``)."""

    def __init__(self, pieces, program, part):
        self.pieces = list(pieces)
        self.refs = [piece_reference(pc, program, part) for pc in self.pieces]
        self._tree = cKDTree(np.vstack([pc.points for pc in self.pieces]))

    def kinds(self) -> dict[str, int]:
        """How many pieces of each kind (line, arc, offsets)."""
        out: dict[str, int] = {}
        for r in self.refs:
            out[r.kind] = out.get(r.kind, 0) + 1
        return out

    def stream_error(self, positions: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """(N,) distance of each stream row to the exact path of its own piece (mm)."""
        err = np.zeros(len(positions))
        for j, ref in enumerate(self.refs):
            sel = rows == j
            if sel.any():
                err[sel] = ref.distance(positions[sel])
        return err

    def distance(self, p: np.ndarray) -> np.ndarray:
        """(K,) distance of each point to the nearest piece's exact path (mm): pieces whose
        points come within NEAR of the nearest piece's are measured (cheap ones first)."""
        p = np.atleast_2d(p)
        best = np.full(len(p), np.inf)
        for ref in self.refs:   # lines and arcs are cheap: all of them
            if ref.kind not in ("offsets", "guided"):
                best = np.minimum(best, ref.distance(p))
        d0, _ = self._tree.query(p)
        for ref in self.refs:   # a corner path where its points are near enough
            if ref.kind in ("offsets", "guided"):
                dj, _ = ref._tree.query(p)
                sel = dj <= np.minimum(best, d0) + ref.h + NEAR
                if sel.any():
                    best[sel] = np.minimum(best[sel], ref.distance(p[sel]))
        return best


def summary(err: np.ndarray) -> tuple[float, float]:
    """(max, p99) of an error array (mm)."""
    return float(err.max()), float(np.percentile(err, 99))
