"""The path against OCCT's own intersection of the two offset surfaces.

OCCT (GeomAPI_IntSS on Geom_OffsetSurface) returns one or more curves; the *branch* is the
chain of those curves the path's points are nearest to, ordered and oriented along the
path. Everything after that is measured on a dense sampling of the branch (spacing
``spacing`` mm, exact curve points) plus exact OCCT point-to-curve projections for the
path's own points. Lengths in mm.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.tolerances import DEFAULT, Tolerances
from . import probe as occt
from .check_records import ReferenceCheck


def nearest(a: np.ndarray, b: np.ndarray, chunk: int = 64) -> np.ndarray:
    """Index into ``b`` of the nearest point to each row of ``a`` (brute force, chunked)."""
    out = np.empty(len(a), dtype=int)
    bb = (b * b).sum(axis=1)
    for i in range(0, len(a), chunk):
        blk = a[i:i + chunk]
        d2 = bb[None, :] - 2.0 * blk @ b.T
        out[i:i + chunk] = np.argmin(d2, axis=1)
    return out


def polyline_distance(points: np.ndarray, poly: np.ndarray, closed: bool = False,
                      same: float = DEFAULT.closed) -> np.ndarray:
    """Distance from each point to the polyline ``poly`` (M, 3).

    The segments near the one with the nearest midpoint are measured exactly (midpoints,
    unlike vertices, stay distinct where a closed polyline returns to its start).
    ``closed``: the last vertex joins the first, neighbours wrap around. Vertices closer
    than ``same`` mm are one vertex.
    """
    if len(poly) > 1:  # repeated vertices would hide a neighbouring segment
        keep = np.concatenate([[True], np.linalg.norm(np.diff(poly, axis=0), axis=1) > same])
        poly = poly[keep]
    if len(poly) < 2:
        return np.linalg.norm(points - poly[0], axis=1)
    if closed and np.linalg.norm(poly[-1] - poly[0]) > same:
        poly = np.vstack([poly, poly[:1]])
    a_all, b_all = poly[:-1], poly[1:]
    idx = nearest(points, 0.5 * (a_all + b_all))
    best = np.full(len(points), np.inf)
    for shift in (-2, -1, 0, 1, 2):
        j = (idx + shift) % len(a_all) if closed else np.clip(idx + shift, 0, len(a_all) - 1)
        a, ab = a_all[j], b_all[j] - a_all[j]
        t = np.clip(((points - a) * ab).sum(axis=1) / (ab * ab).sum(axis=1), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(points - (a + t[:, None] * ab), axis=1))
    return best


def _coverage(chain, s, lo, hi, points, cover_radius):
    """(fraction covered, gaps, span length, branch samples) of the branch on [lo, hi].

    A branch sample is covered when it lies within ``cover_radius`` of a cutter centre;
    the fraction is the length between covered samples over the span's length (0 for an
    empty span); gaps are the uncovered stretches (from, to) in mm from ``lo``.
    """
    keep = (s >= lo) & (s <= hi)
    seg = chain[keep]
    if len(seg) < 2:
        return 0.0, [], hi - lo, seg
    cd = np.linalg.norm(seg - points[nearest(seg, points)], axis=1)
    covered = cd <= cover_radius
    ss = s[keep] - lo
    ds = np.diff(ss)
    both = covered[1:] & covered[:-1]
    total = float(ds.sum())
    gaps, run = [], None
    for i, c in enumerate(covered):
        if not c and run is None:
            run = ss[max(i - 1, 0)]
        elif c and run is not None:
            gaps.append((float(run), float(ss[i])))
            run = None
    if run is not None:
        gaps.append((float(run), float(ss[-1])))
    return (float(ds[both].sum() / total) if total > 0 else 0.0), gaps, hi - lo, seg


def _sample(curve, points, extra, spacing, tol: Tolerances):
    """Parameters and points of a curve densely sampled where the path can be."""
    t0, t1 = curve.FirstParameter(), curve.LastParameter()
    if not (math.isfinite(t0) and math.isfinite(t1)) or max(abs(t0), abs(t1)) > 1e50:
        probe = np.vstack([points[:: max(1, len(points) // 20)], points[-1:], extra])
        ts = occt.curve_params(curve, probe)
        ts = ts[np.isfinite(ts)]
        margin = 0.1 * (ts.max() - ts.min()) + 1.0
        t0, t1 = ts.min() - margin, ts.max() + margin
    _, coarse = occt.sample_curve(curve, t0, t1, 400)
    length = float(np.linalg.norm(np.diff(coarse, axis=0), axis=1).sum())
    n = int(min(max(length / spacing, 400), 200_000))
    ts, pts = occt.sample_curve(curve, t0, t1, n)
    closed = bool(np.linalg.norm(pts[0] - pts[-1]) < tol.closed)
    return ts, pts, closed


def check_reference(surface_a, surface_b, points: np.ndarray, *, span: str,
                    target=None, cover_radius: float, spacing: float = 0.01,
                    residual_probes=(), tol: Tolerances = DEFAULT) -> ReferenceCheck:
    """Compare ``points`` (N, 3) with the intersection of two (offset) Geom surfaces.

    ``span``: "closed" (the branch once around), "end" (the path's own end is the
    intended end), or "target" (``target`` (3,) is the intended end, the path may have
    stopped short of it). ``residual_probes``: (FaceProbe, offset) pairs to measure how
    far OCCT's curve is from the offset surfaces. ``tol.closed``: a sampled curve whose
    ends are closer than this is a loop; polyline vertices closer than this coincide.
    """
    curves, seconds = occt.intersect(surface_a, surface_b, tol.intersection)
    rep = ReferenceCheck(n_curves=len(curves), occt_seconds=seconds,
                         cover_radius_mm=cover_radius)
    if not curves:
        rep.note = "OCCT found no intersection of the offset surfaces"
        return rep
    extra = np.zeros((0, 3)) if target is None else np.asarray(target, float)[None]
    sampled = [_sample(c, points, extra, spacing, tol) for c in curves]
    allpts = np.vstack([s[1] for s in sampled])
    owner = np.concatenate([np.full(len(s[1]), k) for k, s in enumerate(sampled)])
    local = np.concatenate([np.arange(len(s[1])) for s in sampled])
    near = nearest(points, allpts)
    piece_of = owner[near]
    # a piece met only by the path's first or last point is met where pieces join (a path
    # starting or ending where two pieces meet): those points belong to the piece the path
    # runs along
    at_end = np.minimum(np.linalg.norm(points - points[0], axis=1),
                        np.linalg.norm(points - points[-1], axis=1)) <= cover_radius
    lone = [k for k in set(piece_of.tolist()) if at_end[piece_of == k].all()]
    if lone and len(set(piece_of.tolist())) > len(lone):
        keep = ~np.isin(owner, lone)
        moved = np.isin(piece_of, lone)
        near[moved] = np.flatnonzero(keep)[nearest(points[moved], allpts[keep])]
        piece_of = owner[near]
    # the branch: the pieces the path runs along, in the order the path meets them
    order = sorted(set(piece_of.tolist()), key=lambda k: int(np.argmax(piece_of == k)))
    rep.branch_curves = order
    chain = []
    for k in order:
        ts, pts, closed = sampled[k]
        idx = local[near[piece_of == k]]
        m = len(pts)
        if closed:
            pts = pts[:-1]
            m -= 1
            start = idx[0] % m
            steps = (idx - idx[0]) % m
            moved = steps[(steps > 2) & (steps < m - 2)]
            forward = not len(moved) or np.median(np.where(moved < m / 2, 1, -1)) >= 0
            roll = np.roll(pts, -start, axis=0)
            pts = roll if forward else np.vstack([roll[:1], roll[1:][::-1]])
            pts = np.vstack([pts, pts[:1]])
        elif len(idx) > 1 and idx[-1] < idx[0]:
            pts = pts[::-1]
        chain.append(pts)
    chain = np.vstack(chain)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(chain, axis=0), axis=1))])
    # exact distances of the cutter centres to the branch (OCCT projection on the curve)
    d = np.empty(len(points))
    for i, p in enumerate(points):
        k = piece_of[i]
        ts = sampled[k][0]
        j = local[near[i]]
        lo, hi = ts[max(j - 3, 0)], ts[min(j + 3, len(ts) - 1)]
        res = occt.project_on_curve(curves[k], p, lo, hi)
        d[i] = res[1] if res is not None else np.linalg.norm(p - allpts[near[i]])
    rep.points_to_branch = d
    rep.points_worst_cycle = int(np.argmax(d))
    rep.points_max_mm = float(d.max())
    mids = 0.5 * (points[1:] + points[:-1])
    mid_d = (polyline_distance(mids, chain, span == "closed", tol.closed) if len(mids)
             else np.zeros(0))
    rep.path_to_branch_mm = float(max(d.max(), mid_d.max() if len(mid_d) else 0.0))
    # the span: from the path's start to its intended end along the branch
    s_path = s[nearest(points, chain)]
    s0 = float(s_path[0])
    if span == "closed":
        s1 = float(s[-1])
    elif span == "target" and target is not None:
        s1 = float(s[nearest(np.asarray(target, float)[None], chain)[0]])
    else:
        s1 = float(s_path[-1])
    closed_path = span == "closed" and len(points) > 2 and np.linalg.norm(
        points[-1] - points[0]) <= cover_radius / 0.6
    # Hausdorff over the path's own span (start to its last point, or the loop)
    s_last = float(s[-1]) if closed_path else float(s_path[-1])
    lo, hi = min(s0, s_last), max(s0, s_last)
    own = chain[(s >= lo) & (s <= hi)]
    if len(own) and len(points) > 1:
        rep.branch_to_path_mm = float(polyline_distance(own, points, closed_path,
                                                        tol.closed).max())
    else:
        rep.branch_to_path_mm = 0.0
    rep.hausdorff_mm = max(rep.path_to_branch_mm, rep.branch_to_path_mm)
    # curve coverage over the path's own span (start to its last point, or the loop)
    own = _coverage(chain, s, min(s0, s_last), max(s0, s_last), points, cover_radius)
    rep.coverage, rep.own_span_mm = own[0], own[2]
    # and over the intended span (start to the intended end): the gaps, what remains
    lo, hi = min(s0, s1), max(s0, s1)
    rep.intended_coverage, rep.gaps, rep.span_mm, seg = _coverage(chain, s, lo, hi, points,
                                                                  cover_radius)
    if len(seg) < 2:
        rep.note = "the path's span on the reference branch is empty"
        return rep
    # the reference's own accuracy: OCCT's curve against the offset surfaces
    probe_pts = seg[np.linspace(0, len(seg) - 1, 24).astype(int)]
    worst = 0.0
    for probe, off in residual_probes:
        for q in probe_pts:
            pr = probe.project_global(q, whole_surface=True)
            if pr is not None:
                worst = max(worst, abs(pr[2] - off))
    rep.residual_mm = worst
    return rep
