"""Where a finishing operation's guide planes go: fixed or scallop-driven spacing.

The ball centre runs on vertical planes ``dot(p, n) = d`` with n = (-sin A, cos A, 0)
(A the pass angle). The planes cover the ball centres that touch the selected faces:
from the smallest to the largest ``n . (p + R' N)`` over samples p of the faces (N the
outward normal). With a stepover S they are S apart, centred on that range (at most S/2
from either end). With a scallop height H they are placed one after another, each as far
from the last as every sample between them allows (docs/finish.md, "Spacing"):

    c = 2 sqrt(2 R H - H^2) sqrt(B / A) sqrt(1 - s^2),   s^2 = (2 R H - H^2) k^2 / (4 A B)
    A = |1 - (C + H) k|,  B = |1 - R' k|,  Delta = c_i g_j,  g = sqrt(1 - (n . N)^2)

c is the distance between neighbouring ball centres across the passes that leaves a cusp
H high on the surface offset by the allowance C (ball R, R' = R + C; k the surface's normal
curvature across the passes, the sign of docs/method.md: < 0 convex), exact for a
circular cross-section; g turns that distance on the offset surface into the distance
between the planes (a slope across the passes brings them closer): the smallest c_i g_j
over the samples i between two planes and the samples j on i's cross-section between
them within c_i (:mod:`.slope`: the chord through a sample is set by the slope all
across the strip, not at the sample alone). Samples
the ball cannot serve are set apart with their reason: normals pointing down
(``unreachable``), concave tighter than the ball (``too tight``), within
``PARALLEL_DEG`` of parallel to the planes (``parallel wall``). Where a face's boundary
runs along or obliquely to the planes, a plane whose contact leaves the face there ends its
pass far along the edge; the edge is cut from the next plane inside, or from that pass's
end, each within half a chord (:func:`along_edges`, :func:`edge_intervals`). Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from ...core.errors import InputError
from ...core.trim_labels import OUTSIDE
from ...core.work_limits import MAX_PLANES, refuse_over
from .polish import face_derivatives
from .slope import strip_pairs

PARALLEL_DEG = 5.0
"""deg: a face whose normal is this near the planes' normal is a wall parallel to them."""
DOWN_NZ = -1e-9
"""A sample whose normal's Z is below this points down: the ball cannot reach it from +Z."""
MAX_SAMPLES = 60_000
"""Samples over all the selected faces at most (the grid is made coarser above)."""
MIN_PER_SIDE = 4
EDGE_ALONG = 0.9
"""A boundary along which the centre coordinate changes slower than this many times g mm per
mm (g = sqrt(1 - (n . N)^2), the planes' spacing over the chord) needs a plane near it
(:func:`along_edges`); from 1 on, planes a spacing apart serve it (between 0.9 and 1 they
leave at most (2 / 1.9)^2 H, where the planes are a whole spacing apart)."""
EDGE_STEEP_DEG = 60.0
"""deg: boundary samples steeper than this get no edge interval."""
EDGE_INSET = 0.125
"""The plane serving such a boundary lies at least this many spacings inside the face."""
ESTIMATE_BINS = 2048
"""Bins of the plane coordinate over which the adaptive spacing's plane count is estimated."""


@dataclass
class FaceSamples:
    """Samples of the selected faces on a grid of nodes over each face's (u, w) box (its
    edges included), nodes outside the trims dropped: (N, 3) points, normals (outward), r_u, r_w, r_uu, r_uw, r_ww;
    (N,) face numbers and areas (mm^2, the node's trapezoid share of the face); ``spacing`` mm."""

    points: np.ndarray
    normals: np.ndarray
    ru: np.ndarray
    rw: np.ndarray
    ruu: np.ndarray
    ruw: np.ndarray
    rww: np.ndarray
    faces: np.ndarray
    areas: np.ndarray
    spacing: float
    edge: np.ndarray | None = None
    """(N,) whether the node lies on its face's boundary: a border of the grid that is not
    a seam, or beside a node outside the trims (None: not known)."""

    def __len__(self) -> int:
        return len(self.points)


def sample_faces(part, faces, spacing: float, max_samples: int = MAX_SAMPLES) -> FaceSamples:
    """Samples of ``faces`` (numbers of ``part``) about ``spacing`` mm apart on the surface,
    coarser when that would give more than ``max_samples`` in all."""
    surfs = [part.face(n) for n in faces]
    extents = [s.parameter_lengths() for s in surfs]
    total = sum(lu * lw for lu, lw in extents) / spacing ** 2
    if total > max_samples:
        spacing *= math.sqrt(total / max_samples)
    numbers, weights, derivs, edge = [], [], [], []
    for s, (lu, lw) in zip(surfs, extents):
        nu = max(MIN_PER_SIDE, math.ceil(lu / spacing))
        nw = max(MIN_PER_SIDE, math.ceil(lw / spacing))
        (u0, u1), (w0, w1) = s.u_range, s.w_range
        us, wu = _nodes(u0, u1, nu)
        ws, ww = _nodes(w0, w1, nw)
        inside = s.classify_grid(us, ws) != OUTSIDE
        numbers.extend([s.number] * int(inside.sum()))
        weights.extend((wu[:, None] * ww[None, :])[inside].tolist())
        wrap = [per is not None and abs(hi - lo - per) <= 1e-9 * max(1.0, per)  # whole period
                for per, (lo, hi) in ((s.u_period, s.u_range), (s.w_period, s.w_range))]
        edge.extend(_edge_nodes(inside, *wrap)[inside].tolist())
        uv = np.stack(np.meshgrid(us, ws, indexing="ij"), axis=-1).reshape(-1, 2)
        uv = uv[inside.ravel()]
        if len(uv):   # D2 at every node at once (compiled where the face allows)
            derivs.extend(face_derivatives(s, uv))
    if not derivs:
        raise InputError(f"faces {', '.join(map(str, faces))}: no sample inside their trims")
    d = np.array(derivs)                                   # (N, 6, 3)
    c = np.cross(d[:, 1], d[:, 2])
    area = np.linalg.norm(c, axis=1)
    scale = (d[:, 1] ** 2).sum(1) + (d[:, 2] ** 2).sum(1) + 1e-300   # no / 0
    tol = {s.number: s.tol.singular for s in surfs}
    sign = {s.number: s.normal_sign for s in surfs}
    numbers = np.array(numbers)
    # a pole (|r_u x r_w| / (|r_u|^2 + |r_w|^2) below the face's tolerance, as
    # FaceSurface.singularity): no normal; its cell has no area either
    keep = area / scale >= np.array([tol[n] for n in numbers])
    if not keep.any():
        raise InputError(f"faces {', '.join(map(str, faces))}: no sample inside their trims")
    d, c, area, numbers = d[keep], c[keep], area[keep], numbers[keep]
    normals = np.array([sign[n] for n in numbers])[:, None] * c / area[:, None]
    return FaceSamples(d[:, 0], normals, d[:, 1], d[:, 2], d[:, 3], d[:, 4], d[:, 5],
                       numbers, area * np.array(weights)[keep], spacing,
                       np.array(edge, bool)[keep])


def _edge_nodes(inside: np.ndarray, wrap_u: bool, wrap_w: bool) -> np.ndarray:
    """(nu + 1, nw + 1) whether each grid node is on the face's boundary: on a border of
    the grid not joined to the opposite one (``wrap_u``, ``wrap_w``: a closed seam), or
    beside a node outside the trims (4-neighbours)."""
    pad = np.pad(inside, 1, constant_values=False)
    if wrap_u:
        pad[0, 1:-1], pad[-1, 1:-1] = inside[-2], inside[1]
    if wrap_w:
        pad[1:-1, 0], pad[1:-1, -1] = inside[:, -2], inside[:, 1]
    return inside & ~(pad[:-2, 1:-1] & pad[2:, 1:-1] & pad[1:-1, :-2] & pad[1:-1, 2:])


def _nodes(t0: float, t1: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n + 1 nodes from t0 to t1 and their trapezoid weights (summing to t1 - t0)."""
    w = np.full(n + 1, (t1 - t0) / n)
    w[[0, -1]] *= 0.5
    return np.linspace(t0, t1, n + 1), w


def plane_normal(angle_deg: float) -> np.ndarray:
    """(3,) the guide planes' unit normal for pass angle A: (-sin A, cos A, 0)."""
    a = math.radians(angle_deg)
    return np.array([-math.sin(a), math.cos(a), 0.0])


def across(samples: FaceSamples, normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, g), each (N,): the normal curvature (1/mm, < 0 convex) of each sample in the
    direction across the passes (the planes' ``normal`` projected on the tangent plane),
    and g = |that projection| = sqrt(1 - (normal . N)^2) (0 on a wall parallel to them)."""
    nn = samples.normals
    e = normal[None, :] - (nn @ normal)[:, None] * nn
    g = np.linalg.norm(e, axis=1)
    ru, rw = samples.ru, samples.rw
    E, F, G = (ru * ru).sum(1), (ru * rw).sum(1), (rw * rw).sum(1)
    L, M, N = ((samples.ruu * nn).sum(1), (samples.ruw * nn).sum(1),
               (samples.rww * nn).sum(1))
    tu, tw = (ru * e).sum(1), (rw * e).sum(1)
    det = E * G - F * F
    a, b = (G * tu - F * tw) / det, (E * tw - F * tu) / det
    den = E * a * a + 2 * F * a * b + G * b * b
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(den > 0, (L * a * a + 2 * M * a * b + N * b * b) / den, 0.0)
    return k, g


def centre_chord(h, k, radius: float, allowance: float = 0.0):
    """The distance (mm) between neighbouring ball centres across the passes that leaves a
    cusp ``h`` mm high on a surface of normal curvature ``k`` (1/mm, < 0 convex) across
    them, ball ``radius`` R with ``allowance`` C (the module doc's c; exact for a circular
    cross-section). 0 where the ball does not fit (R' k >= 1). A cusp can be no higher
    than the ball: h is taken at most R (the chord of h >= R is that of R, at most 2 R
    on a flat floor). Arrays broadcast."""
    h, k = np.minimum(np.asarray(h, float), radius), np.asarray(k, float)
    r1 = radius + allowance
    w = 2.0 * radius * h - h * h
    A = np.abs(1.0 - (allowance + h) * k)
    B = 1.0 - r1 * k
    fits = B > 0
    B = np.where(fits, B, 1.0)
    s2 = np.minimum(w * k * k / (4.0 * A * B), 0.5)  # at most a quarter turn apart
    return np.where(fits, 2.0 * np.sqrt(w * B / A * (1.0 - s2)), 0.0)


def stepover_scallop(stepover: float, radius: float) -> float:
    """The cusp height (mm) of passes ``stepover`` mm apart on a flat floor, ball R."""
    half = min(stepover / 2.0, radius)
    return radius - math.sqrt(radius * radius - half * half)


@dataclass
class PlanePlan:
    """The guide planes of one operation: ``angle`` (deg), ``offsets`` (P,) ascending (mm
    along ``normal``); per sample its centre coordinate ``f`` (N,) and ``reason``
    (N,) ("" a sample the planes serve; "unreachable", "too tight", "parallel wall")."""

    angle: float
    normal: np.ndarray
    offsets: np.ndarray
    f: np.ndarray
    reason: np.ndarray
    spacing: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """(N,) the plane spacing each sample allows (mm; scallop mode, else empty)."""


def sample_reasons(samples: FaceSamples, k, g, offset: float) -> np.ndarray:
    """(N,) why the planes cannot serve each sample ("" when they can)."""
    reason = np.full(len(samples), "", dtype=object)
    reason[g < math.sin(math.radians(PARALLEL_DEG))] = "parallel wall"
    reason[k * offset >= 1.0] = "too tight"
    reason[samples.normals[:, 2] < DOWN_NZ] = "unreachable"
    return reason


def plan_planes(samples: FaceSamples, radius: float, allowance: float, angle: float, *,
                stepover: float | None = None, scallop: float | None = None,
                max_planes: int = MAX_PLANES, work: dict | None = None) -> PlanePlan:
    """The guide planes over ``samples`` (see the module doc). Their number is estimated
    before any is placed (:func:`planes_estimate`) and refused over ``max_planes``
    (:class:`~cadcnc.core.work_limits.WorkLimitError`, naming the option that brings it down);
    ``work``: a dict given ``planes_estimate``."""
    work = {} if work is None else work
    r1 = radius + allowance
    n = plane_normal(angle)
    k, g = across(samples, n)
    q = samples.points + r1 * samples.normals
    f = q @ n
    reason = sample_reasons(samples, k, g, r1)
    reach = reason != "unreachable"
    if not reach.any():
        return PlanePlan(angle, n, np.zeros(0), f, reason)
    lo, hi = float(f[reach].min()), float(f[reach].max())
    if stepover is not None:
        count = work["planes_estimate"] = planes_estimate(lo, hi, stepover=stepover)
        refuse_over(f"finishing {hi - lo:.4g} mm across the planes (R' {r1:g} mm) at a "
                    f"stepover of {stepover:g} mm", count, max_planes, "guide planes",
                    "give a larger --stepover, or a smaller --radius")
        count = int(count)
        first = 0.5 * (lo + hi) - 0.5 * (count - 1) * stepover
        return PlanePlan(angle, n, first + stepover * np.arange(count), f, reason)
    c, serve = centre_chord(scallop, k, radius, allowance), reason == ""
    spacing = np.where(serve, c * g, np.inf)
    pairs, bound = strip_pairs(samples, q, f, n, k, g, c, serve, r1)
    estimate = work["planes_estimate"] = planes_estimate(lo, hi, f=f, spacing=bound)
    refuse_over(f"finishing {hi - lo:.4g} mm across the planes (R' {r1:g} mm) for a "
                f"scallop of {scallop:g} mm", estimate, max_planes, "guide planes",
                "give a larger --scallop, or a smaller --radius")
    a, e = edge_intervals(*along_edges(samples, f, g), f, spacing)
    extra = int(np.ceil((e.max() - a.min()) / (e - a).min())) + 1 if len(a) else 0
    offsets = adaptive_offsets(f, spacing, lo, hi, limit=int(1.5 * estimate) + 2 + extra,
                               edges=(a, e), pairs=pairs)
    return PlanePlan(angle, n, offsets, f, reason, spacing)


def along_edges(samples: FaceSamples, f: np.ndarray, g: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """(side, slope), each (N,): for each boundary sample (``samples.edge``) where the
    face's boundary runs obliquely to the planes (the centre coordinate ``f`` (N,) changes
    by less than ``EDGE_ALONG`` g (N,) mm per mm to its two nearest boundary samples of the
    same face: the larger of the two, over g, is ``slope``), the side of f the face lies on (+1 or -1: its
    nearest samples' mean); 0 elsewhere. There the pass of the plane on the outer side
    leaves the face, its end 1 / slope times farther along the edge than the plane is
    across it (:func:`edge_intervals`)."""
    side, slope = np.zeros(len(samples)), np.ones(len(samples))
    if samples.edge is None:
        return side, slope
    for face in np.unique(samples.faces):
        mine = np.flatnonzero(samples.faces == face)
        idx = mine[samples.edge[mine]]
        if len(idx) < 3:
            continue
        p = samples.points[idx]
        dist, near = cKDTree(p).query(p, k=3)
        s = (np.abs(f[idx][near[:, 1:]] - f[idx][:, None])
             / np.maximum(dist[:, 1:], 1e-12)).max(axis=1) / np.maximum(g[idx], 1e-12)  # no / 0
        # on a steep edge (over EDGE_STEEP_DEG) the planes are close already (g small);
        # in steep-shallow it is waterline's
        steep = samples.normals[idx, 2] < math.cos(math.radians(EDGE_STEEP_DEG))
        along = (s < EDGE_ALONG) & ~steep
        inner = cKDTree(samples.points[mine]).query(p[along], k=min(9, len(mine)))[1]
        side[idx[along]] = np.sign((f[mine][inner] - f[idx[along]][:, None]).mean(axis=1))
        slope[idx[along]] = s[along]
    return side, slope


def edge_intervals(side: np.ndarray, slope: np.ndarray, f: np.ndarray, spacing: np.ndarray):
    """(a, e): for each boundary sample at ``f`` running obliquely to the planes (``side``
    != 0, ``slope`` s < 1, finite ``spacing``; all (N,)), the interval of f (mm) that must
    hold a plane so that the edge's cusp stays within H there. A plane within half a chord
    on the face's side passes over the sample; one on the outer side at f - x leaves the
    face x / s along the edge from it: within half a chord when x <= s c / 2. The interval
    runs from ``EDGE_INSET`` of a spacing inside (a plane along the edge itself would run
    on it; at s = 0) to s c / 2 outside (at s = 1), linearly in s: a part of [f - s c / 2,
    f + c / 2] (mirrored for side -1), c the sample's spacing."""
    sel = (side != 0) & np.isfinite(spacing)
    half, inner, s = 0.5 * spacing[sel], EDGE_INSET * spacing[sel], slope[sel]
    near = inner - (inner + half) * np.clip(s, 0.0, 1.0)   # towards the face from f
    lo = np.where(side[sel] > 0, f[sel] + near, f[sel] - half)
    return lo, np.where(side[sel] > 0, f[sel] + half, f[sel] - near)


def planes_estimate(lo: float, hi: float, *, stepover: float | None = None, f=None,
                    spacing=None) -> float:
    """How many planes cover centre coordinates ``lo`` .. ``hi`` (mm), before any is
    placed: ``stepover`` apart, exactly ceil((hi - lo) / S) (at least 1); or adaptively
    (:func:`adaptive_offsets`) for samples at ``f`` (N,) allowing ``spacing`` (N,):
    the sum over ESTIMATE_BINS bins of the bin's width over the smallest spacing of the
    samples from it to one widest spacing ahead (what a step from the bin can take), at
    least 1. NaN (refused) when a spacing is 0 or not a number."""
    if stepover is not None:
        return float(max(1, math.ceil((hi - lo) / stepover - 1e-9)))  # ceil's round-off
    sp = np.asarray(spacing, float)
    fin = np.isfinite(sp)
    if np.isnan(sp).any() or (sp[fin] <= 0).any():
        return math.nan
    if not fin.any() or hi <= lo:
        return 1.0
    widest = float(sp[fin].max())
    width = (hi - lo) / ESTIMATE_BINS
    at = np.clip(((np.asarray(f)[fin] - lo) / width).astype(np.int64), 0, ESTIMATE_BINS - 1)
    least = np.full(ESTIMATE_BINS, widest)
    np.minimum.at(least, at, sp[fin])
    ahead = min(ESTIMATE_BINS, math.ceil(widest / width))
    padded = np.r_[least, np.full(ahead, widest)]
    window = np.lib.stride_tricks.sliding_window_view(padded, ahead + 1).min(axis=1)
    return max(1.0, float((width / window).sum()) + 1.0)


def adaptive_offsets(f: np.ndarray, spacing: np.ndarray, lo: float, hi: float,
                     limit: int = MAX_PLANES, edges=None, pairs=None) -> np.ndarray:
    """Plane offsets from ``lo`` to ``hi`` (mm): the first within half the spacing its
    samples allow of ``lo``, each next as far from the last as the smallest ``spacing``
    (N,) of the samples whose ``f`` (N,) lies between them, the last within half a spacing
    of ``hi``. ``edges``: intervals (a, e) (M,) each of which must hold a plane: a next
    plane comes no later than the first end e of an interval starting after the last
    (the greedy stabbing). ``pairs`` (fi, lo_j, hi_j, v) (P,): a spacing v binding the
    planes where fi lies between them and [lo_j, hi_j] meets them (:mod:`.slope`). More
    than ``limit`` planes is an error (the estimate was wrong)."""
    order = np.argsort(f)
    fs, sp = f[order], spacing[order]
    finite = sp[np.isfinite(sp)]
    if not len(finite):
        return np.array([0.5 * (lo + hi)])
    widest = float(finite.max())
    a, e = (np.zeros(0), np.zeros(0)) if edges is None else map(np.asarray, edges)
    by = np.argsort(a)
    a = a[by]
    ends = np.minimum.accumulate(e[by][::-1])[::-1] if len(a) else e   # min end of a[i:]
    pi, plo, phi, pv = (np.zeros(0),) * 4 if pairs is None else pairs
    po = np.argsort(pi)
    pi, plo, phi, pv = pi[po], plo[po], phi[po], pv[po]

    def allowed(x: float) -> float:
        """The smallest spacing of the samples in [x, x + d], shrinking d to it."""
        d = widest
        for _ in range(60):
            i, j = np.searchsorted(fs, x, side="left"), np.searchsorted(fs, x + d, side="right")
            m = float(sp[i:j].min()) if j > i else math.inf
            i, j = np.searchsorted(pi, x, side="left"), np.searchsorted(pi, x + d, side="right")
            on = (phi[i:j] >= x) & (plo[i:j] <= x + d)
            m = min(m, float(pv[i:j][on].min(initial=math.inf)))
            if m >= d:
                return d
            d = m
        return d

    def due(x: float, strict: bool = True) -> float:
        """The first end of the intervals starting after x (inf when none)."""
        i = np.searchsorted(a, x, side="right" if strict else "left")
        return float(ends[i]) if i < len(a) else math.inf

    out = [min(lo + 0.5 * allowed(lo), due(lo, strict=False))]
    while True:
        d = allowed(out[-1])
        nxt = due(out[-1])
        if out[-1] + 0.5 * d >= hi and nxt == math.inf:
            break
        if len(out) >= limit:
            raise RuntimeError(f"adaptive spacing: more than {limit} planes, over 1.5 times "
                               "the estimate")
        out.append(min(out[-1] + d, nxt))
    return np.array(out)
