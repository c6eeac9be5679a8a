"""O(1) trim check: a uniform (u, w) grid of cells labelled inside / outside / mixed.

``TrimGrid.build(face_surface).classify(u, w)`` returns exactly ``FaceSurface.classify(u,
w)`` (FClass2d.Perform on the wrapped point, same tolerance); only MIXED cells call FClass2d.

Why the labels are exact: FClass2d classifies against its own polygon per wire (pcurve
samples, ``NbSamples`` x 4 per edge, re-sampled by ``GCPnts_QuasiUniformDeflection`` on thin
wires) with a band of half-widths Tu = max(FlecheU, tol), Tv = max(FlecheV, tol): a point is
ON (sent to BRepClass_FaceClassifier) only if the polygon meets the box p +- (Tu, Tv); off the
bands the answer is ray-crossing parity, constant on any connected set meeting no band;
``Perform`` also tries the point shifted by whole periods. ``fclass_polygon`` rebuilds
FClass2d's polygons and bands (same OCCT calls and parameter arithmetic; long pcurves
evaluated compiled, OCCT deciding wherever round-off could matter); every cell touched by a
band, a copy of one whole periods away or the wrap's seam (+ 1e-12 relative round-off) is
MIXED; the other cells form 4-connected regions, each labelled by one exact call at a cell
centre, confirmed by two more (disagreement or ON: the region stays MIXED, counted in
``stats["suspect"]``). Where FClass2d uses BRepClass for every point (bad wire, <= 3 points,
no pcurve, flat box) or its periods differ from FaceSurface's, the grid is one MIXED cell
(``stats["exact_only"]``).

Resolution rule: a boundary with total variations Lu = sum |du_k|, Lw = sum |dw_k| makes about
Lu dw + Lw du of MIXED area, so N cells over the grid box Du x Dw are best shaped du = sqrt(C
Lu / Lw), dw = sqrt(C Lw / Lu), C = Du Dw / N, for a MIXED share of the face box Fu x Fw of
about 2 sqrt(Lu Lw C) / (Fu Fw); N makes that ``target_share`` (2 %), within [256,
``max_cells`` = 4096] (benchmarks/kernel/bench_trim_grid.py). A periodic direction whose bands cover
over 3/4 of the period spans exactly the wrap range; any other spans the bands + 1.1 clear
cells each side (periodic ones inside a one-period window centred on them), so a point
beyond the grid takes its nearest border cell's label.

MIXED cells (``trim_cells.segment_blocks``) keep the band segments that meet them (seam and
periodic copies included). ``cadcnc.interp.kernel.trim_lookup.resolve`` answers a point of such a cell with the
label of a labelled neighbour cell when the axis-parallel move from the point to their
shared side, swept by each segment's half-widths + eps (FClass2d's own ON test), meets no
segment: that rectangle and the neighbour form a connected set meeting no band, so
FClass2d's answer is the neighbour's. Only a point that no such move clears (inside a band,
where FClass2d itself turns to BRepClass, or boxed in between bands) is classified exactly.
``kernel_args`` hands codes and segment lists to ``cadcnc.interp.kernel.trim_lookup.lookup``, the reader the
kernel and ``cell`` share.
"""

from __future__ import annotations

import math
import time
from itertools import product

import numpy as np
from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
from OCP.gp import gp_Pnt2d
from OCP.TopAbs import TopAbs_IN, TopAbs_ON, TopAbs_OUT

from ..core.trim_labels import BOUNDARY, CELL_INSIDE, CELL_MIXED, CELL_OUTSIDE, INSIDE, OUTSIDE
from ..interp.kernel.trim_lookup import lookup, lookup_grid
from .fclass_polygon import classifier_tolerance, polygon_bands  # noqa: F401 (re-exported)
from .trim_cells import layout, paint, regions, segment_blocks, segment_lists


def _free_cells(bands, face_surface, max_cells: int, target: float) -> tuple:
    """(origin (2,), cell size (2,), mask (nu, nw) uint8, windows, segments): the layout, and
    the cells (mask 1) that a band, or its copies whole periods away, or the wrap's seam
    touches; segments: (p, q, h, eps, start, ids), those bands and which touch each cell
    (``trim_cells.segment_lists``)."""
    p, q, h = bands
    lo, hi = (np.minimum(p, q) - h).min(axis=0), (np.maximum(p, q) + h).max(axis=0)
    axes, windows = layout(lo, hi, p, q, face_surface, max_cells, target)
    origin, size = np.array([a[0] for a in axes]), np.array([a[1] for a in axes])
    shape = np.array([axes[0][2], axes[1][2]])
    eps = 1e-12 * (np.abs(origin) + shape * size) + 1e-300   # round-off of a cell edge, > 0
    shifts = [[k * t for k in range(math.ceil((o - b) / t) - 1,
                                    math.floor((o + n * s - a) / t) + 2)] if t else [0.0]
              for a, b, o, s, n, (_, t, _) in zip(lo, hi, origin, size, shape, windows)]
    grid_lo, grid_hi = origin - eps, origin + shape * size + eps
    moved = np.array([m for m in product(*shifts)  # copies wholly beyond the grid touch nothing
                      if np.all(lo + m <= grid_hi) and np.all(hi + m >= grid_lo)])[:, None, :]
    segs = [(p + moved).reshape(-1, 2), (q + moved).reshape(-1, 2), np.tile(h, (len(moved), 1))]
    for k, (_, _, seam) in enumerate(windows):
        if seam is not None:  # a line across the grid
            a, b = origin - size, origin + (shape + 1) * size
            a[k] = b[k] = seam
            segs = [np.vstack([x, y]) for x, y in zip(segs, (a[None], b[None], np.zeros((1, 2))))]
    mask, start, ids = segment_lists(*segs, origin, size, eps, int(shape[0]), int(shape[1]))
    return origin, size, mask, windows, (*segs, eps, start, ids)


_STATE_CODE = {TopAbs_IN: CELL_INSIDE, TopAbs_OUT: CELL_OUTSIDE}
_CODE_STATE = {CELL_INSIDE: INSIDE, CELL_OUTSIDE: OUTSIDE}


class TrimGrid:
    """Cell labels (nu, nw) int8 over [u0, u0 + nu du] x [w0, w0 + nw dw] of one face.

    ``classify(u, w)`` is ``face_surface.classify(u, w)``, O(1) outside MIXED cells. The
    kernel: ``lookup(*kernel_args, *to_window(u, w))`` (``window`` = (u start, u period,
    w start, w period), period 0 where not periodic; ``cadcnc.interp.kernel.trim_lookup.wrap`` does to_window).
    ``stats``: build_s (s), regions, calls (exact calls at build), suspect, exact_only.
    """

    def __init__(self, face_surface, labels: np.ndarray, origin, size, windows,
                 classifier, stats: dict):
        self.face, self.labels, self.stats, self._fc = face_surface, labels, stats, classifier
        (self.u0, self.w0), (self.du, self.dw) = map(float, origin), map(float, size)
        self.window = tuple(float(x) for win in windows for x in win[:2])
        self.nu, self.nw = labels.shape
        self.codes, self.fine = labels.astype(np.int64), np.zeros(0)  # no segment lists

    @classmethod
    def build(cls, face_surface, max_cells: int = 4096, target_share: float = 0.02,
              checks: int = 3, sub_cells: int = 256, data=None) -> "TrimGrid":
        """Label a grid for ``face_surface`` (a FaceSurface) by the module's rule, with
        ``checks`` (1..3) exact calls per region (the first decides, the others confirm);
        ``sub_cells`` > 1: MIXED cells keep their segments (``cadcnc.interp.kernel.trim_lookup.resolve``), 1:
        they always defer to FClass2d. ``data``: the face's SurfaceData, if built already
        (its B-spline poles are reused)."""
        t_start = time.perf_counter()
        tol_uv = classifier_tolerance(face_surface)
        fc = getattr(face_surface, "_classifier", None)  # FaceSurface.classify's, if made
        if fc is None:  # the same classifier (face, tolerance) FaceSurface.classify builds
            fc = face_surface._classifier = BRepTopAdaptor_FClass2d(face_surface.topods, tol_uv)
        bands = polygon_bands(face_surface, tol_uv, data)
        stats = {"exact_only": bands is None, "regions": 0, "suspect": 0, "calls": 0}
        if bands is None or not len(bands[0]):  # exact only, or no wire (all IN): one cell
            origin, size, windows = (0.0, 0.0), (1.0, 1.0), [(0.0, 0.0)] * 2
            mask, segs = np.full((1, 1), bands is None, np.uint8), None
        else:
            origin, size, mask, windows, segs = _free_cells(bands, face_surface, max_cells,
                                                            target_share)
        grid = cls(face_surface, np.full(mask.shape, CELL_MIXED, np.int8), origin, size,
                   windows, fc, stats)
        grid._label_regions(mask, checks)
        if segs is not None and sub_cells > 1:
            p, q, h, eps, start, ids = segs
            grid.codes, grid.fine = segment_blocks(grid.labels, start, ids, p, q, h, eps)
        grid.cell(grid.u0, grid.w0)  # loads the reader for Python once (not in a step)
        stats["build_s"] = time.perf_counter() - t_start
        return grid

    @classmethod
    def whole(cls, face_surface) -> "TrimGrid":
        """One cell, inside, for a face whose boundary is never asked (``FaceSurface.whole``:
        a guide plane in a stream, whose steppers check no boundary): every point reads
        inside, with no exact call and no build."""
        stats = {"exact_only": False, "regions": 0, "suspect": 0, "calls": 0, "build_s": 0.0}
        return cls(face_surface, np.full((1, 1), CELL_INSIDE, np.int8), (0.0, 0.0),
                   (1.0, 1.0), [(0.0, 0.0)] * 2, None, stats)

    def _label_regions(self, mask: np.ndarray, checks: int) -> None:
        """One exact call per 4-connected region of free cells (mask 0; plus confirmations)."""
        region, picks = regions(mask)
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
        paint(self.labels, region, code)
        self.codes = self.labels.astype(np.int64)

    def to_window(self, u: float, w: float) -> tuple[float, float]:
        """(u, w) moved by whole periods into the grid's window, as ``lookup`` expects."""
        us, pu, ws, pw = self.window
        return (us + (u - us) % pu if pu else u), (ws + (w - ws) % pw if pw else w)

    def cell(self, u: float, w: float) -> int:
        """The label of (u, w), given in the window (CELL_MIXED if not finite), read as the
        kernel reads it (``cadcnc.interp.kernel.trim_lookup.lookup``)."""
        return lookup(self.codes, self.fine, self.u0, self.w0, self.du, self.dw, self.nu,
                      self.nw, u, w)

    def classify(self, u: float, w: float) -> str:
        """inside / boundary / outside, exactly as ``FaceSurface.classify``."""
        code = self.cell(*self.to_window(u, w))
        return _CODE_STATE[code] if code != CELL_MIXED else self._exact(u, w)

    def _exact(self, u: float, w: float) -> str:
        """FClass2d's answer at (u, w), as ``FaceSurface.classify`` gives it."""
        state = self._fc.Perform(gp_Pnt2d(*self.face.wrap(u, w)))
        return INSIDE if state == TopAbs_IN else BOUNDARY if state == TopAbs_ON else OUTSIDE

    def classify_grid(self, us: np.ndarray, ws: np.ndarray) -> np.ndarray:
        """(len(us), len(ws)) object array: ``classify(u, w)`` of every node of the grid
        ``us`` x ``ws`` (parameters), the labelled cells read in one compiled call and
        only the MIXED ones asked of FClass2d."""
        us, ws = np.ascontiguousarray(us, float), np.ascontiguousarray(ws, float)
        codes = np.empty((len(us), len(ws)), np.int64)
        lookup_grid(*self.kernel_args, np.array(self.window), us, ws, codes)
        out = np.where(codes == CELL_INSIDE, INSIDE, OUTSIDE).astype(object)
        for a, b in zip(*np.nonzero(codes == CELL_MIXED)):
            out[a, b] = self._exact(float(us[a]), float(ws[b]))
        return out

    @property
    def kernel_args(self) -> tuple:
        """(codes, fine, u0, w0, du, dw, nu, nw): the leading arguments of
        ``cadcnc.interp.kernel.trim_lookup.lookup``."""
        return self.codes, self.fine, self.u0, self.w0, self.du, self.dw, self.nu, self.nw
