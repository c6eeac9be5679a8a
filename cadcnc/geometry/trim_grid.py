"""O(1) trim check: a uniform (u, w) grid of cells labelled inside / outside / mixed.

``TrimGrid.build(face_surface).classify(u, w)`` returns exactly ``FaceSurface.classify(u,
w)`` (FClass2d.Perform on the wrapped point, same tolerance); only MIXED cells call FClass2d.

Why the labels are exact: FClass2d classifies against its own polygon per wire (pcurve
samples, ``NbSamples`` x 4 per edge, re-sampled by ``GCPnts_QuasiUniformDeflection`` on thin
wires) with a band of half-widths Tu = max(FlecheU, tol), Tv = max(FlecheV, tol): a point is
ON (sent to BRepClass_FaceClassifier) only if the polygon meets the box p +- (Tu, Tv); off the
bands the answer is ray-crossing parity, constant on any connected set meeting no band;
``Perform`` also tries the point shifted by whole periods. ``_bands`` rebuilds FClass2d's
polygons and bands (same OCCT calls and parameter arithmetic); every cell touched by a band, a
copy of one whole periods away or the wrap's seam (+ 1e-12 relative round-off) is MIXED; the
other cells form 4-connected regions, each labelled by one exact call at a cell centre,
confirmed by two more (disagreement or ON: the region stays MIXED, counted in
``stats["suspect"]``). Where FClass2d uses BRepClass for every point (bad wire, <= 3 points,
no pcurve, flat box) or its periods differ from FaceSurface's, the grid is one MIXED cell
(``stats["exact_only"]``).

Resolution rule: a boundary with total variations Lu = sum |du_k|, Lw = sum |dw_k| makes about
Lu dw + Lw du of MIXED area, so N cells over the grid box Du x Dw are best shaped du = sqrt(C
Lu / Lw), dw = sqrt(C Lw / Lu), C = Du Dw / N, for a MIXED share of the face box Fu x Fw of
about 2 sqrt(Lu Lw C) / (Fu Fw); N makes that ``target_share`` (2 %), within [256,
``max_cells`` = 65536] (64 KiB; benchmarks/bench_trim_grid.py). A periodic direction whose
bands cover over 3/4 of the period spans exactly the wrap range; any other spans the bands +
1.1 clear cells each side (periodic ones inside a one-period window centred on them), so a
point beyond the grid takes its nearest border cell's label.

Sub-cells (``trim_cells.refine``): each MIXED cell is split in up to ``sub_cells`` (256)
sub-cells, thin strips where its bands run along u or w (a periodic face's seam edge), else
up to 4 x 4; a sub-cell is MIXED if a band segment meets it inflated by the half-widths
(FClass2d's own ON test, + the 1e-12 round-off margin); free sub-cells connected inside the
cell take the label of the free cells beside them (they agree, or the sub-cells stay MIXED:
``stats["unresolved"]``). ``kernel_args`` hands both levels to ``trim_lookup.lookup``.
"""

from __future__ import annotations

import math
import time
from itertools import product

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
from OCP.GCPnts import GCPnts_QuasiUniformDeflection
from OCP.Geom2dInt import Geom2dInt_Geom2dCurveTool
from OCP.gp import gp_Pnt2d
from OCP.TopAbs import (TopAbs_FORWARD, TopAbs_IN, TopAbs_ON, TopAbs_OUT, TopAbs_REVERSED,
                        TopAbs_WIRE)
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS

from .trim_cells import layout, mark, refine, regions
from ..trim import BOUNDARY, CELL_INSIDE, CELL_MIXED, CELL_OUTSIDE, INSIDE, OUTSIDE

_CONFUSION = 1e-7  # OCCT Precision::Confusion(), mm


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


def _keep_distinct(seq: list, pts: list, us: list, du: float, c3, last3d):
    """Append to ``seq`` the samples FClass2d keeps: a point repeating the last kept one in
    3-D is dropped unless the half-step point differs; returns the last kept 3-D point.
    Vectorised when no two successive points are that close (then every point is kept)."""
    p3 = [c3.Value(t).Coord() for t in us]
    if not p3:
        return last3d
    a = np.array(p3 if last3d is None else [last3d] + p3)
    d = a[1:] - a[:-1]
    if len(d) == 0 or (d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2]).min() >= \
            _CONFUSION * _CONFUSION * (1.0 + 1e-9):
        seq += pts
        return p3[-1]
    for (x, y), t, q in zip(pts, us, p3):
        real = True
        if len(seq) > 1 and last3d is not None and _distance(q, last3d) < _CONFUSION:
            real = _distance(q, c3.Value(t - du / 2.0).Coord()) >= _CONFUSION
        if real:
            seq.append((x, y))
            last3d = q
    return last3d


def _fleches(seq: list, before: int, fu: float, fv: float) -> tuple[float, float]:
    """``_fleche`` over every point appended after ``before`` (from the fifth one on) whose
    triple's ends differ, as FClass2d checks after each sample; vectorised."""
    if len(seq) <= before + 4:
        return fu, fv
    a = np.asarray(seq[before + 2:], dtype=float)
    pa, pb, pc = a[:-2], a[1:-1], a[2:]
    use = np.any(pa != pc, axis=1)
    pa, pb, pc = pa[use], pb[use], pc[use]
    n = np.hypot(pc[:, 0] - pa[:, 0], pc[:, 1] - pa[:, 1])
    pa, pb, pc, n = pa[n > 0], pb[n > 0], pc[n > 0], n[n > 0]
    if not len(n):
        return fu, fv
    d = (pc - pa) / n[:, None]
    t = (pb[:, 0] - pa[:, 0]) * d[:, 0] + (pb[:, 1] - pa[:, 1]) * d[:, 1]
    return (max(fu, float(np.abs(pa[:, 0] + t * d[:, 0] - pb[:, 0]).max())),
            max(fv, float(np.abs(pa[:, 1] + t * d[:, 1] - pb[:, 1]).max())))


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


def _sample(wire, face, box: list, defl: float = 0.0) -> tuple[list, float, float, int] | None:
    """FClass2d's polygon of one wire: (points, FlecheU, FlecheV, edges walked). ``defl`` > 0:
    its re-sampling pass (quasi-uniform deflection, no 3-D test, ``box`` left alone)."""
    seq, fu, fv, first_point, walked, last3d = [], 0.0, 0.0, 1, 0, None
    for item in _edges(wire, face):
        if item is None:
            return None
        walked += 1
        edge, orient, pf, pl = item
        if abs(pl - pf) < 1e-9:
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
        us = []
        for _ in range(first_point, nbs + 1):  # the same running sum as FClass2d's
            us.append(u)
            u += du
        pts = [c2.Value(t).Coord() for t in us]
        if pts:
            xs, ys = zip(*pts)
            box[:] = min(box[0], *xs), max(box[1], *xs), min(box[2], *ys), max(box[3], *ys)
        before = len(seq)
        if degenerated:
            seq += pts
        else:
            last3d = _keep_distinct(seq, pts, us, du, c3, last3d)
        fu, fv = _fleches(seq, before, fu, fv)
        first_point = 2
    return seq, fu, fv, walked


def _thickness(seq: list) -> float:
    """FClass2d's 2 |area| / perimeter (its loop skips the last point; NaN if no perimeter)."""
    b = np.roll(a := np.asarray(seq)[:-1], 1, axis=0)
    square = float(np.sum((a[:, 0] - b[:, 0]) * (a[:, 1] + b[:, 1]) * 0.5))
    per = float(np.sum(np.hypot(*(a - b).T)))
    return max(2.0 * abs(square) / per, 1e-7) if per > 0.0 else math.nan


def _bands(face_surface, tol_uv: float) -> tuple[np.ndarray, ...] | None:
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
        first = _sample(wire, face, box)
        if first is None or first[3] != wire.NbChildren():  # the explorer missed edges
            return None
        seq, fu, fv, _ = first
        if not seq:
            continue
        if len(seq) <= 3:
            return None
        thick, defl = _thickness(seq), max(fu, fv)
        discr = min(defl * 0.1, thick * 10.0)
        while defl > thick and discr > 1e-7:
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


def _free_cells(bands, face_surface, max_cells: int, target: float) -> tuple:
    """(origin (2,), cell size (2,), mask (nu, nw) uint8, windows, segments): the layout, and
    the cells (mask 1) that a band, or its copies whole periods away, or the wrap's seam
    touches; segments (p, q, h, eps) are those bands for ``trim_cells.refine``."""
    p, q, h = bands
    lo, hi = (np.minimum(p, q) - h).min(axis=0), (np.maximum(p, q) + h).max(axis=0)
    axes, windows = layout(lo, hi, p, q, face_surface, max_cells, target)
    origin, size = np.array([a[0] for a in axes]), np.array([a[1] for a in axes])
    shape = np.array([axes[0][2], axes[1][2]])
    eps = 1e-12 * (np.abs(origin) + shape * size) + 1e-300
    shifts = [[k * t for k in range(math.ceil((o - b) / t) - 1,
                                    math.floor((o + n * s - a) / t) + 2)] if t else [0.0]
              for a, b, o, s, n, (_, t, _) in zip(lo, hi, origin, size, shape, windows)]
    moved = np.array(list(product(*shifts)))[:, None, :]  # every copy in one pass
    segs = [(p + moved).reshape(-1, 2), (q + moved).reshape(-1, 2), np.tile(h, (len(moved), 1))]
    for k, (_, _, seam) in enumerate(windows):
        if seam is not None:  # a line across the grid
            a, b = origin - size, origin + (shape + 1) * size
            a[k] = b[k] = seam
            segs = [np.vstack([x, y]) for x, y in zip(segs, (a[None], b[None], np.zeros((1, 2))))]
    mask = np.zeros(shape, dtype=np.uint8)
    mark(mask, *segs, origin, size, eps)
    return origin, size, mask, windows, (*segs, eps)


_STATE_CODE = {TopAbs_IN: CELL_INSIDE, TopAbs_OUT: CELL_OUTSIDE}
_CODE_STATE = {CELL_INSIDE: INSIDE, CELL_OUTSIDE: OUTSIDE}


class TrimGrid:
    """Cell labels (nu, nw) int8 over [u0, u0 + nu du] x [w0, w0 + nw dw] of one face.

    ``classify(u, w)`` is ``face_surface.classify(u, w)``, O(1) outside MIXED cells. The
    kernel: ``lookup(*kernel_args, *to_window(u, w))`` (``window`` = (u start, u period,
    w start, w period), period 0 where not periodic; ``trim_lookup.wrap`` does to_window).
    ``stats``: build_s (s), regions, calls (exact calls at build), suspect, exact_only.
    """

    def __init__(self, face_surface, labels: np.ndarray, origin, size, windows,
                 classifier, stats: dict):
        self.face, self.labels, self.stats, self._fc = face_surface, labels, stats, classifier
        (self.u0, self.w0), (self.du, self.dw) = map(float, origin), map(float, size)
        self.window = tuple(float(x) for win in windows for x in win[:2])
        self.nu, self.nw = labels.shape
        self.codes, self.fine = labels.astype(np.int64), np.zeros(0, np.int64)  # no sub-cells
        self._flat = labels.tobytes()  # C order: cell (i, j) at i * nw + j

    @classmethod
    def build(cls, face_surface, max_cells: int = 65536, target_share: float = 0.02,
              checks: int = 3, sub_cells: int = 256) -> "TrimGrid":
        """Label a grid for ``face_surface`` (a FaceSurface) by the module's rule, with
        ``checks`` (1..3) exact calls per region (the first decides, the others confirm)
        and up to ``sub_cells`` sub-cells per MIXED cell (1: none)."""
        t_start = time.perf_counter()
        tol_uv = classifier_tolerance(face_surface)
        fc = BRepTopAdaptor_FClass2d(face_surface.topods, tol_uv)
        bands = _bands(face_surface, tol_uv)
        stats = {"exact_only": bands is None, "regions": 0, "suspect": 0, "calls": 0}
        if bands is None or not len(bands[0]):  # exact only, or no wire (all IN): one cell
            origin, size, windows = (0.0, 0.0), (1.0, 1.0), [(0.0, 0.0)] * 2
            mask, segs = np.full((1, 1), bands is None, np.uint8), None
        else:
            origin, size, mask, windows, segs = _free_cells(bands, face_surface, max_cells,
                                                            target_share)
        grid = cls(face_surface, np.full(mask.shape, CELL_MIXED, np.int8), origin, size,
                   windows, fc, stats)
        grid._label_regions(mask == 0, checks)
        if segs is not None and sub_cells > 1:
            grid.codes, grid.fine, stats["unresolved"] = refine(
                mask, grid.labels, *segs[:3], np.asarray(origin), np.asarray(size), segs[3],
                sub_cells, min(sub_cells, 16))
        stats["build_s"] = time.perf_counter() - t_start
        return grid

    def _label_regions(self, free: np.ndarray, checks: int) -> None:
        """One exact call per 4-connected region of free cells (plus confirmations)."""
        region, picks = regions(np.ascontiguousarray(~free, dtype=np.uint8))
        if not len(picks):
            return
        code = np.empty(len(picks), dtype=np.int8)
        for r, cells in enumerate(picks.tolist()):
            states = {_STATE_CODE.get(self._fc.Perform(gp_Pnt2d(*self.face.wrap(
                self.u0 + (c // self.nw + 0.5) * self.du,
                self.w0 + (c % self.nw + 0.5) * self.dw))), CELL_MIXED)
                for c in cells[:max(1, checks)]}
            code[r] = label = states.pop() if len(states) == 1 else CELL_MIXED
            self.stats["suspect"] += label == CELL_MIXED
        self.stats.update(regions=len(picks), calls=len(picks) * min(max(1, checks), 3))
        self.labels[region >= 0] = code[region[region >= 0]]
        self._flat = self.labels.tobytes()

    def to_window(self, u: float, w: float) -> tuple[float, float]:
        """(u, w) moved by whole periods into the grid's window, as ``lookup`` expects."""
        us, pu, ws, pw = self.window
        return (us + (u - us) % pu if pu else u), (ws + (w - ws) % pw if pw else w)

    def cell(self, u: float, w: float) -> int:
        """The label of the cell holding (u, w), given in the window (CELL_MIXED if not finite)."""
        x, y = (u - self.u0) / self.du, (w - self.w0) / self.dw
        if not (abs(x) < 1e15 and abs(y) < 1e15):
            return CELL_MIXED
        i = min(max(math.floor(x), 0), self.nu - 1)
        j = min(max(math.floor(y), 0), self.nw - 1)
        code = self._flat[i * self.nw + j]
        if code != CELL_MIXED or not self.fine.size:
            return code
        k = int(self.codes[i, j]) - 3  # trim_lookup.lookup's sub-cell, from Python
        if k < 0:
            return code
        ru, rw = int(self.fine[k]), int(self.fine[k + 1])
        a, b = min(max(math.floor((x - i) * ru), 0), ru - 1), min(max(math.floor((y - j) * rw), 0), rw - 1)
        return int(self.fine[k + 2 + a * rw + b])

    def classify(self, u: float, w: float) -> str:
        """inside / boundary / outside, exactly as ``FaceSurface.classify``."""
        code = self.cell(*self.to_window(u, w))
        if code != CELL_MIXED:
            return _CODE_STATE[code]
        state = self._fc.Perform(gp_Pnt2d(*self.face.wrap(u, w)))
        return INSIDE if state == TopAbs_IN else BOUNDARY if state == TopAbs_ON else OUTSIDE

    @property
    def kernel_args(self) -> tuple:
        """(codes, fine, u0, w0, du, dw, nu, nw): the leading arguments of
        ``trim_lookup.lookup``."""
        return self.codes, self.fine, self.u0, self.w0, self.du, self.dw, self.nu, self.nw
