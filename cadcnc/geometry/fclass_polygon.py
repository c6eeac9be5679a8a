"""FClass2d's polygon and bands of a face, rebuilt for the trim grid (geometry/trim_grid.py).

``polygon_bands(face_surface, tol_uv)`` samples each wire's pcurves with FClass2d's own rule
(``NbSamples`` x 4 per edge, the same running parameter sum, 3-D repeats dropped, sag
estimates, the quasi-uniform re-sampling of thin wires) and returns the segments and their
half-widths. The samples are evaluated in one numpy pass (``polygon_points``) where the
geometry allows, with OCCT's own calls as the fallback and the arbiter of every decision
taken near a threshold (module trim_grid explains why round-off there is harmless).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.GCPnts import GCPnts_QuasiUniformDeflection
from OCP.Geom2dInt import Geom2dInt_Geom2dCurveTool
from OCP.TopAbs import TopAbs_FORWARD, TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS

from ..core.tolerances import CONFUSION
from .polygon_points import pcurve_points, surface_points

_CONFUSION = CONFUSION  # OCCT Precision::Confusion(), mm
_FAST_FROM = 32  # samples of an edge from which numpy evaluates them (fewer: OCCT's calls)


def classifier_tolerance(face_surface) -> float:
    """FaceSurface's FClass2d tolerance in (u, w): ``tol.on_boundary`` mm via the resolutions."""
    adaptor, tol = BRepAdaptor_Surface(face_surface.topods, True), face_surface.tol.on_boundary
    return min(adaptor.UResolution(tol), adaptor.VResolution(tol))


def _fleche(seq: list, fu: float, fv: float) -> tuple[float, float]:
    """FClass2d's sag estimate at the last three points: middle one against the chord."""
    (ax, ay), (bx, by), (cx, cy) = seq[-3:]
    n = math.hypot(cx - ax, cy - ay)
    if n == 0.0:
        return fu, fv
    dx, dy = (cx - ax) / n, (cy - ay) / n
    t = (bx - ax) * dx + (by - ay) * dy
    return max(fu, abs(ax + t * dx - bx)), max(fv, abs(ay + t * dy - by))


def _distance(a: tuple, b: tuple) -> float:
    """gp_Pnt::Distance's arithmetic (squares summed in x, y, z order)."""
    d = 0.0
    for x, y in zip(a, b):
        d += (x - y) * (x - y)
    return math.sqrt(d)


def _keep_distinct(kept: int, uv: np.ndarray, us, du: float, c3, last, p3=None):
    """The samples ``uv`` (k, 2) at parameters ``us`` that FClass2d keeps after ``kept``
    points of the wire: a point repeating the last kept one in 3-D is dropped unless the
    half-step point differs. ``last``: None or (the last kept 3-D point, its curve, its
    parameter). Returns (kept points (m, 2), the new ``last``). ``p3`` (k, 3): the 3-D points
    from numpy (round-off from OCCT's), trusted only when every successive distance clears
    Confusion by 1 % (then every point is kept); otherwise OCCT's own points decide."""
    if not len(us):
        return uv, last
    if p3 is not None and _min_gap2(np.array(last[0] if last else (np.nan,) * 3), p3) >= \
            (_CONFUSION * 1.01) ** 2:
        return uv, (tuple(p3[-1]), c3, float(us[-1]))
    us = [float(t) for t in us]
    p3 = [c3.Value(t).Coord() for t in us]
    last3d = None if last is None else last[1].Value(last[2]).Coord()
    a = np.array(p3 if last3d is None else [last3d] + p3)
    d = a[1:] - a[:-1]
    if len(d) == 0 or (d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2]).min() >= \
            _CONFUSION * _CONFUSION * (1.0 + 1e-9):   # relative round-off
        return uv, (p3[-1], c3, us[-1])
    out = []
    for (x, y), t, q in zip(uv.tolist(), us, p3):
        real = True
        if kept + len(out) > 1 and last is not None and _distance(q, last[0]) < _CONFUSION:
            real = _distance(q, c3.Value(t - du / 2.0).Coord()) >= _CONFUSION
        if real:
            out.append((x, y))
            last = q, c3, t
    return np.array(out, dtype=float).reshape(-1, 2), last


@numba.njit(cache=True, nogil=True)
def _extend(box: np.ndarray, uv: np.ndarray) -> tuple[float, float, float, float]:
    """(umin, umax, wmin, wmax) of ``box`` (4,) and the points uv (k, 2)."""
    u0, u1, w0, w1 = box[0], box[1], box[2], box[3]
    for k in range(len(uv)):
        u0, u1 = min(u0, uv[k, 0]), max(u1, uv[k, 0])
        w0, w1 = min(w0, uv[k, 1]), max(w1, uv[k, 1])
    return u0, u1, w0, w1


@numba.njit(cache=True, nogil=True)
def _min_gap2(first: np.ndarray, p3: np.ndarray) -> float:
    """The smallest squared distance between successive points of ``first`` (3,) (left out
    if NaN) followed by p3 (k, 3); inf if there is no pair."""
    best = math.inf
    for k in range(len(p3)):
        a = first if k == 0 else p3[k - 1]
        if k == 0 and math.isnan(first[0]):
            continue
        d = (p3[k, 0] - a[0]) ** 2 + (p3[k, 1] - a[1]) ** 2 + (p3[k, 2] - a[2]) ** 2
        best = min(best, d)
    return best


def _close(fast: np.ndarray, exact: tuple) -> bool:
    """Whether a numpy point agrees with OCCT's to round-off (1e-12 of its size)."""
    return bool(np.abs(fast - exact).max() <= 1e-12 * (1.0 + np.abs(exact).max()))  # round-off


def _fast_points(c2, c3, surface, us: np.ndarray, data=None):
    """(2-D points (n, 2), 3-D points (n, 3) or None) from numpy, each checked against
    OCCT at its first and last sample; (None, None) where the pcurve is not supported."""
    uv = pcurve_points(c2, us)
    if uv is None or not all(_close(uv[k], c2.Value(us[k]).Coord()) for k in (0, -1)):
        return None, None
    xyz = surface_points(surface, uv, data)
    if xyz is not None:
        t = surface.Trsf()
        m = np.array([[t.Value(i, j) for j in range(1, 5)] for i in range(1, 4)])
        xyz = xyz @ m[:, :3].T + m[:, 3]
        if not all(_close(xyz[k], c3.Value(us[k]).Coord()) for k in (0, -1)):
            xyz = None
    return uv, xyz


@numba.njit(cache=True, nogil=True)
def _fleches(a: np.ndarray, fu: float, fv: float) -> tuple[float, float]:
    """``_fleche`` over the points an edge appended (``a`` (k, 2)) from the fifth one on
    whose triple's ends differ, as FClass2d checks after each sample (compiled)."""
    for k in range(4, len(a)):
        ax, ay, bx, by = a[k - 2, 0], a[k - 2, 1], a[k - 1, 0], a[k - 1, 1]
        cx, cy = a[k, 0], a[k, 1]
        if ax == cx and ay == cy:
            continue
        n = math.hypot(cx - ax, cy - ay)
        if n == 0.0:
            continue
        dx, dy = (cx - ax) / n, (cy - ay) / n
        t = (bx - ax) * dx + (by - ay) * dy
        fu = max(fu, abs(ax + t * dx - bx))
        fv = max(fv, abs(ay + t * dy - by))
    return fu, fv


def _is_degenerated(c3: BRepAdaptor_Curve, first: float, last: float) -> bool:
    """FClass2d's test: no 3-D sample farther than Confusion (squared!) from the start."""
    step, start, u = (last - first) * 0.1, c3.Value(first), first
    while u < last:
        if start.SquareDistance(c3.Value(u)) > _CONFUSION:
            return False
        u = u + step if u + step != u else math.nextafter(u, last)
    return True


def _edges(wire, face):
    """(edge, orientation, first, last) along the wire as FClass2d walks it; None if a
    FORWARD/REVERSED edge has no pcurve (FClass2d stops building there)."""
    explorer = BRepTools_WireExplorer()
    explorer.Init(wire, face)
    while explorer.More():
        edge = explorer.Current()
        orient = edge.Orientation()
        if orient not in (TopAbs_FORWARD, TopAbs_REVERSED):
            yield edge, orient, 0.0, 0.0  # skipped, as FClass2d does: an empty range
        elif BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0) is None:
            yield None
            return
        else:
            yield edge, orient, *BRep_Tool.Range_s(edge, face)
        explorer.Next()


def _sample(wire, face, box: list, defl: float = 0.0, surface=None,
            data=None) -> tuple[list, float, float, int] | None:
    """FClass2d's polygon of one wire: (points (k, 2), FlecheU, FlecheV, edges walked).
    ``defl`` > 0: its re-sampling pass (quasi-uniform deflection, no 3-D test, ``box`` left alone).
    ``surface`` (the face's BRepAdaptor_Surface): evaluate the samples in numpy where
    supported (``_fast_points``; ``data``: the face's SurfaceData, if any); None: OCCT's
    calls only."""
    seq, fu, fv, first_point, walked, last3d, kept = [], 0.0, 0.0, 1, 0, None, 0
    chunks = [np.zeros((0, 2))]  # the kept points, edge by edge (seq: re-sampled ones)
    for item in _edges(wire, face):
        if item is None:
            return None
        walked += 1
        edge, orient, pf, pl = item
        if abs(pl - pf) < 1e-9:   # an edge of no parameter range: skipped
            continue
        c2, c3 = BRepAdaptor_Curve2d(edge, face), BRepAdaptor_Curve(edge, face)
        if defl:
            discr = GCPnts_QuasiUniformDeflection(c2, defl)
            if not discr.IsDone():
                break
            idx = list(range(1, discr.NbPoints() + 1))[::1 if orient == TopAbs_FORWARD else -1]
            seq += [c2.Value(discr.Parameter(i)).Coord() for i in idx[first_point - 1:]]
            fu, fv = _fleche(seq, fu, fv) if len(idx) > 2 else (fu, fv)
            first_point = 2
            continue
        degenerated = (BRep_Tool.Degenerated_s(edge) or BRep_Tool.IsClosed_s(edge, face)
                       or TopExp.FirstVertex_s(edge).IsNull()
                       or TopExp.LastVertex_s(edge).IsNull() or _is_degenerated(c3, pf, pl))
        nbs = Geom2dInt_Geom2dCurveTool.NbSamples_s(c2)
        nbs = nbs * 4 if nbs > 2 else nbs
        du = (pl - pf) / (nbs - 1) * (1.0 if orient == TopAbs_FORWARD else -1.0)
        u = (pf if orient == TopAbs_FORWARD else pl) + (du if first_point == 2 else 0.0)
        count = nbs + 1 - first_point
        uv = xyz = None
        if surface is not None and count >= _FAST_FROM:
            us = np.full(count, du)
            us[0] = u
            us = np.cumsum(us)  # the same running sum as FClass2d's (in order)
            uv, xyz = _fast_points(c2, c3, surface, us, data)
        else:
            us = []
            for _ in range(count):  # the same running sum as FClass2d's
                us.append(u)
                u += du
        if uv is None:
            uv = np.array([c2.Value(t).Coord() for t in us]).reshape(-1, 2)
        if len(uv):
            box[:] = _extend(np.array(box), uv)
        if not degenerated:
            uv, last3d = _keep_distinct(kept, uv, us, du, c3, last3d, xyz)
        chunks.append(uv)
        kept += len(uv)
        fu, fv = _fleches(uv, fu, fv)
        first_point = 2
    return (np.asarray(seq, dtype=float).reshape(-1, 2) if defl else np.concatenate(chunks)), \
        fu, fv, walked


def _thickness(seq: list) -> float:
    """FClass2d's 2 |area| / perimeter (its loop skips the last point; NaN if no perimeter)."""
    b = np.roll(a := np.asarray(seq)[:-1], 1, axis=0)
    square = float(np.sum((a[:, 0] - b[:, 0]) * (a[:, 1] + b[:, 1]) * 0.5))
    per = float(np.sum(np.hypot(*(a - b).T)))
    return max(2.0 * abs(square) / per, 1e-7) if per > 0.0 else math.nan  # FClass2d's floor


def polygon_bands(face_surface, tol_uv: float, data=None) -> tuple[np.ndarray, ...] | None:
    """FClass2d's bands: segment starts, ends, half-widths, each (k, 2) in (u, w); None where
    it uses BRepClass for every point. Each wire's closed polygon, plus its CSLib_Class2d box
    outline where a re-sampled polygon leaves that box (the quick rejection then cuts it)."""
    face = TopoDS.Face_s(face_surface.topods.Oriented(TopAbs_FORWARD))
    surface = BRepAdaptor_Surface(face, False)  # FClass2d's view of the periods
    if (surface.IsUPeriodic(), surface.IsVPeriodic()) != (
            face_surface.u_period is not None, face_surface.w_period is not None):
        return None
    box = [0.0, 0.0, 0.0, 0.0]  # FClass2d starts its box at the origin
    p, q, h = [], [], []
    wires = TopExp_Explorer(face, TopAbs_WIRE)
    while wires.More():
        wire = TopoDS.Wire_s(wires.Current())
        wires.Next()
        first = _sample(wire, face, box, surface=surface, data=data)
        if first is None or first[3] != wire.NbChildren():  # the explorer missed edges
            return None
        seq, fu, fv, _ = first
        if not len(seq):
            continue
        if len(seq) <= 3:
            return None
        thick, defl = _thickness(seq), max(fu, fv)
        if defl > thick * (1.0 - 1e-9):  # re-sampling (or nearly): OCCT's own numbers decide
            seq, fu, fv, _ = _sample(wire, face, box)
            thick, defl = _thickness(seq), max(fu, fv)
        discr = min(defl * 0.1, thick * 10.0)
        while defl > thick and discr > 1e-7:   # OCCT FClass2d's loop, its 1e-7
            seq, fu, fv, _ = _sample(wire, face, box, discr)
            thick, defl = _thickness(seq), max(fu, fv)
            discr = min(discr * 0.1, thick * 10.0)
        if box[1] <= box[0] or box[3] <= box[2] or len(seq) < 3:
            return None  # CSLib_Class2d without points: every call goes to BRepClass
        pts, tu, tv = np.asarray(seq, dtype=float), max(fu, tol_uv), max(fv, tol_uv)
        outline = np.array([[box[0] - tu, box[2] - tv], [box[1] + tu, box[2] - tv],
                            [box[1] + tu, box[3] + tv], [box[0] - tu, box[3] + tv]])
        loops = [(pts, (tu, tv))]
        if np.any(pts < outline[0]) or np.any(pts > outline[2]):
            loops.append((outline, (0.0, 0.0)))
        for loop, half in loops:
            p.append(loop)
            q.append(np.roll(loop, -1, axis=0))
            h.append(np.tile(half, (len(loop), 1)))
    return tuple(np.vstack(x) if x else np.zeros((0, 2)) for x in (p, q, h))

