"""The ball against every face of the part: at every cutter centre, and along every move.

Material-aware depth: the ball of radius R' centred at a point outside the solid at
unsigned distance d_k from face k cuts R' - d_k into it; a centre inside the solid cuts
R' + d into the nearest face (d its distance to the whole part). Membership comes from
OCCT's solid classifier (:mod:`.material`); a face's own side says nothing about it (the
centre may be behind a thin wall's far face and still outside). Distances are OCCT's exact
point-to-face (and, where needed, segment-to-face) distances, after a box broad phase and
1-Lipschitz skipping (:mod:`.sweep`). The pair's own faces reuse their per-face check at
the centres. A distance OCCT cannot compute, or a point it cannot classify, counts as a
hit of unknown (nan) depth, never as a miss. Lengths in mm.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..core.tolerances import Tolerances
from .check_records import (
    SurfaceCheck,
    SweepCheck,
    SweepHit,
    WholePartCheck,
    WholePartHit,
    cycle_ranges,
    strict_max,
)
from .material import Material, PartFaces
from .probe import FaceProbe
from .sweep import Polyline

MOVES_BLOCK = 100_000
"""Moves checked at once: a longer polyline (a stream's periods) is checked in blocks of
this many, so that the check's arrays (about 280 bytes a move, 28 MB) stay bounded."""
FAR_MATCH_STEPS = 4.0  # a move farther than 4 steps from the centre found near it is
MATCH_WINDOW = 64      # matched against every centre (a link); else within 64 centres
UNIQUE_REL, UNIQUE_ABS = 1e-9, 1e-12  # a nearest centre nearer than the next by more than
                                      # round-off is the nearest whichever way measured


def check_whole_part(part, probes: dict[int, FaceProbe], toolpath,
                     surfaces: list[SurfaceCheck], ball: float, tol: Tolerances,
                     progress=None, *, moves=None, limit: float | None = None,
                     blend: float = 0.0, faces: PartFaces | None = None,
                     material: Material | None = None,
                     before=None) -> tuple[WholePartCheck, SweepCheck]:
    """Every face of ``part`` against the ball of radius ``ball`` (R'): at every centre
    (a face is hit where the ball reaches deeper than ``tol.hit``), and swept along every
    straight move of ``moves`` ((M, 3) ball centres; default the toolpath's points), which
    must stay within ``limit`` (default ``tol.gouge``) less ``blend``.

    ``probes``: the pair's probes (others are made here); ``surfaces``: the pair's checks.
    ``faces``, ``material``: the part's, shared with other gates (default: made here).
    ``before``: (point (3,), uv (2, 2), faces (2,)) of a centre the moves start beside
    (the previous cut's last): what :func:`before_floors` proves of it bounds the moves.
    """
    limit = tol.gouge if limit is None else limit
    faces = PartFaces(part, probes, tol) if faces is None else faces
    material = Material(faces, tol) if material is None else material
    pts = toolpath.points
    known = {s.face: (np.abs(s.face_deviation + s.offset), s.face_deviation + s.offset)
             for s in surfaces}
    allowance = limit - blend
    centres = Polyline(faces, material, pts, ball, hit=tol.hit,
                       allowance=allowance if moves is None else None, known=known,
                       progress=progress).run()
    whole = _whole(centres, surfaces, ball, tol, len(part), material)
    if moves is None:
        return whole, _sweep(centres, ball, allowance, blend, material)
    moves = np.asarray(moves, float).reshape(-1, 3)
    sweeps = []
    for first in range(0, max(len(moves) - 1, 1), MOVES_BLOCK):
        block = moves[first:first + MOVES_BLOCK + 1]   # the next block starts at its end
        with faces.scratch():   # a block's distances and arrays go before the next's
            floors = None if before is None else before_floors(faces, before, block, tol)
            line = Polyline(faces, material, block, ball, allowance=allowance,
                            anchors=_anchors(centres, block), floors=floors,
                            progress=progress, stage="moves").run()
            sweeps.append((first, _sweep(line, ball, allowance, blend, material)))
            del line
    return whole, sweeps[0][1] if len(sweeps) == 1 else merged_sweeps(sweeps)


def merged_sweeps(blocks: list[tuple[int, SweepCheck]]) -> SweepCheck:
    """One :class:`SweepCheck` of a polyline checked in consecutive blocks, each given
    with the index of its first move: counts summed, bounds and depths the largest (nan
    if any is), each face's hits joined with their moves numbered along the whole."""
    checks = [c for _, c in blocks]
    out = SweepCheck(n_moves=sum(c.n_moves for c in checks),
                     proven=all(c.proven for c in checks),
                     allowance_mm=checks[0].allowance_mm, blend_mm=checks[0].blend_mm,
                     clearance_mm=checks[0].clearance_mm,
                     faces_near=max(c.faces_near for c in checks),
                     distances_evaluated=sum(c.distances_evaluated for c in checks),
                     exact_moves=sum(c.exact_moves for c in checks),
                     classified=sum(c.classified for c in checks))
    out.depth_bound_mm = strict_max(c.depth_bound_mm for c in checks)
    out.depth_mm = strict_max(c.depth_mm for c in checks)
    worst = _worst([c.depth_mm for c in checks])
    out.worst_move = blocks[worst][0] + checks[worst].worst_move
    per_face: dict[int, list[tuple[int, SweepHit]]] = {}
    for first, c in blocks:
        for h in c.hits:
            per_face.setdefault(h.face, []).append((first, h))
    for face in sorted(per_face):
        rows = per_face[face]
        w = _worst([h.depth_mm for _, h in rows])
        ranges: list[list[int]] = []
        for first, h in rows:
            for a, b in h.moves:
                if ranges and ranges[-1][1] + 1 >= first + a:   # joined across blocks
                    ranges[-1][1] = max(ranges[-1][1], first + b)
                else:
                    ranges.append([first + a, first + b])
        out.hits.append(SweepHit(face=face, depth_mm=strict_max(h.depth_mm for _, h in rows),
                                 worst_move=rows[w][0] + rows[w][1].worst_move,
                                 n_moves=sum(h.n_moves for _, h in rows), moves=ranges,
                                 exact=rows[w][1].exact))
    return out


def before_floors(faces: PartFaces, before, moves: np.ndarray, tol: Tolerances) -> dict:
    """{face: (M,) lower bounds of the ``moves``' distances to it} from a centre of
    another cut, ``before`` = (point (3,), uv (2, 2), faces (2,)): on each of its faces,
    OCCT's local search from its own (u, w) finds a foot at distance d, and the surface's
    bound (:meth:`~.probe.FaceProbe.surface_clear`) proves no point of the whole surface
    nearer than d - noise / 2 (else nothing is claimed); the face is no nearer, and a move
    point x at most |x - point| nearer (1-Lipschitz)."""
    point, uv, pair = before
    point = np.asarray(point, float)
    gap = np.linalg.norm(moves - point, axis=1)
    out = {}
    for side, n in enumerate(pair):
        if n is None:
            continue
        probe = faces.probe(n)
        found = probe.project_seeded(point, *uv[side])
        if found is None:
            continue
        u, w, d = found
        floor = d - 0.5 * tol.noise
        if floor > 0.0 and probe.surface_clear(point, u, w, floor):
            out[n] = np.maximum(floor - gap, 0.0)
    return out


def _anchors(centres: Polyline, moves: np.ndarray):
    """(match, centres, {face: distances at the centres}) for :class:`Polyline`.

    Each move is matched to the nearest centre within :data:`MATCH_WINDOW` of the
    previous move's (else to the nearest of all, when that window's is farther than
    :data:`FAR_MATCH_STEPS` steps and another is nearer): :func:`_match`."""
    pts = centres.points
    dists = {}
    for k, (idx, d, _) in centres.samples.items():
        dense = np.full(len(pts), np.nan)
        dense[idx] = d
        dists[k] = dense
    return _match(pts, moves, float(centres.length.max()) if len(centres.length) else 1.0), \
        pts, dists


def _match(pts: np.ndarray, moves: np.ndarray, step: float) -> np.ndarray:
    """(M,) index of the centre each move is matched to (:func:`_anchors`).

    A k-d tree gives each move its two nearest centres; where the nearest is unique (the
    second farther by more than round-off) and lies in the window, it is the window's
    nearest and the rule's answer; elsewhere the window is searched as the rule says."""
    match = np.zeros(len(moves), int)
    if not len(moves):
        return match
    near, idx = cKDTree(pts).query(moves, k=2)
    near = near.reshape(len(moves), -1)
    idx = idx.reshape(len(moves), -1)
    unique = (near[:, -1] > near[:, 0] * (1 + UNIQUE_REL) + UNIQUE_ABS) | (len(pts) < 2)
    at = 0
    for j in range(len(moves)):
        g = int(idx[j, 0])
        if unique[j] and at - MATCH_WINDOW <= g <= at + MATCH_WINDOW:
            at = match[j] = g
            continue
        at = match[j] = window_match(pts, moves[j], at, step)
    return match


def window_match(pts: np.ndarray, m: np.ndarray, at: int, step: float) -> int:
    """The centre of ``pts`` matched to the move ``m`` after a move matched to ``at``:
    the nearest within :data:`MATCH_WINDOW` of ``at``, or the nearest of all when that
    one is farther than :data:`FAR_MATCH_STEPS` ``step`` and another is nearer."""
    lo, hi = max(at - MATCH_WINDOW, 0), min(at + MATCH_WINDOW + 1, len(pts))
    gap = np.linalg.norm(pts[lo:hi] - m, axis=1)
    at = lo + int(np.argmin(gap))
    if gap.min() > FAR_MATCH_STEPS * step:
        far = int(np.argmin(np.linalg.norm(pts - m, axis=1)))
        if np.linalg.norm(pts[far] - m) < gap.min():
            at = far
    return at


def _whole(line: Polyline, surfaces, ball: float, tol: Tolerances, n_faces: int,
           material: Material) -> WholePartCheck:
    """The per-face hits at the centres, from the distances and the membership."""
    n = len(line.points)
    followed = {s.face for s in surfaces}
    state, inside, inside_face = line.state, line.inside, line.inside_face
    depth: dict[int, np.ndarray] = {}
    for k, (idx, d, _) in line.samples.items():
        dense = np.full(n, -np.inf)
        dense[idx] = ball - d  # out of (or on) the material; a face crossed from inside
        depth[k] = dense
    fallback = sorted(followed)[0] if followed else 1
    for j in np.nonzero(state == 2)[0]:  # inside: R' + d into the nearest face
        k = int(inside_face[j]) or int(line.d_face[j]) or fallback
        depth.setdefault(k, np.full(n, -np.inf))[j] = ball + inside[j]
    for j in np.nonzero(state == -1)[0]:  # membership unknown: fail closed
        k = int(line.d_face[j]) or fallback
        depth.setdefault(k, np.full(n, -np.inf))[j] = np.nan
    hits = []
    for k in sorted(depth):
        hit = _hit(k, k in followed, depth[k], tol.hit)
        if hit is not None:
            hits.append(hit)
    every = [a[np.isfinite(a) | np.isnan(a)] for a in depth.values()]
    every = np.concatenate(every) if every else np.zeros(0)
    deepest = np.nan if np.isnan(every).any() else float(max(0.0, every.max(initial=0.0)))
    return WholePartCheck(hits=hits, faces_checked=n_faces,
                          distances_evaluated=line.evaluated + sum(
                              len(s.face_deviation) for s in surfaces),
                          ball_radius_mm=ball, hit_tolerance_mm=tol.hit, max_depth_mm=deepest,
                          faces_near=line.faces_near, material=material.kind,
                          classified=line.classified)


def _sweep(line: Polyline, ball: float, allowance: float, blend: float,
           material: Material) -> SweepCheck:
    """The swept ball along the moves of ``line``: bounds, depths, failing faces."""
    m = len(line.points) - 1
    out = SweepCheck(n_moves=max(m, 0), allowance_mm=allowance, blend_mm=blend,
                     clearance_mm=ball - allowance, faces_near=line.faces_near,
                     distances_evaluated=line.evaluated, exact_moves=line.exact_moves,
                     classified=line.classified)
    if m < 1:
        return out
    state, length = line.state, line.length
    sa, sb = state[:-1], state[1:]
    u = np.where(state == 2, line.inside, 0.0)  # distance to the air, an upper bound
    u = np.where(state == -1, np.nan, u)
    bound = ball - line.seg_lb
    meas = ball - line.seg_meas
    inside = (sa == 2) | (sb == 2)
    lipschitz = ball + 0.5 * (u[:-1] + u[1:] + length)  # depth from the air's distance
    touch = ~(line.seg_lb > 0)
    bound = np.where(inside | (touch & (ball - allowance <= 0)), lipschitz, bound)
    meas = np.where(inside, np.fmax(meas, ball + np.fmax(u[:-1], u[1:])), meas)
    unknown = (sa == -1) | (sb == -1)
    bound[unknown] = meas[unknown] = np.nan
    failed = ~(bound <= allowance)
    out.proven = not failed.any()
    out.depth_bound_mm = float(np.nan if np.isnan(bound).any() else bound.max())
    out.depth_mm = float(np.nan if np.isnan(meas).any() else meas.max())
    out.worst_move = _worst(meas)
    if not out.proven:
        out.hits = _sweep_hits(line, failed, inside | unknown, ball, allowance, meas)
    return out


def _sweep_hits(line: Polyline, failed, blamed_on_nearest, ball, allowance, meas):
    """One record per face the failing moves cut beyond the allowance."""
    per_face: dict[int, list] = {}
    for k, (seg_lb, seg_meas, exact) in line.seg.items():
        bad = np.nonzero(failed & ~(ball - seg_lb <= allowance) & ~blamed_on_nearest)[0]
        for s in bad:
            per_face.setdefault(k, []).append((int(s), ball - seg_meas[s], bool(exact[s])))
    for s in np.nonzero(failed & blamed_on_nearest)[0]:
        j = s if line.state[s] != 0 else s + 1
        k = int(line.inside_face[j]) or int(line.d_face[j]) or int(line.seg_face[s]) or 1
        per_face.setdefault(k, []).append((int(s), float(meas[s]), False))
    named = {r[0] for rows in per_face.values() for r in rows}
    for s in np.nonzero(failed)[0]:  # the touching moves of a ball within the allowance
        if int(s) not in named:
            k = int(line.seg_face[s]) or int(line.d_face[s]) or 1
            per_face.setdefault(k, []).append((int(s), float(meas[s]), False))
    hits = []
    for k in sorted(per_face):
        rows = per_face[k]
        depths = np.array([r[1] for r in rows], float)
        w = _worst(depths)
        hits.append(SweepHit(face=k, depth_mm=float(np.nan if np.isnan(depths).any()
                                                      else depths[w]),
                             worst_move=rows[w][0], n_moves=len(rows),
                             moves=cycle_ranges(sorted(r[0] for r in rows)), exact=rows[w][2]))
    return hits


def _worst(depths) -> int:
    """Index of the deepest of ``depths``; an unmeasured one (nan) counts deepest."""
    depths = np.asarray(depths, float)
    return int(np.argmax(np.where(np.isnan(depths), np.inf, depths)))


def _hit(face: int, followed: bool, depth: np.ndarray, hit_tol: float) -> WholePartHit | None:
    """The face's hit record, or None when the ball stays within ``hit_tol`` of it."""
    unknown = np.isnan(depth)
    hit = np.nonzero((depth > hit_tol) | unknown)[0]
    if not len(hit):
        return None
    if unknown.any():
        worst, deep = int(np.argmax(unknown)), float("nan")
    else:
        worst = int(hit[np.argmax(depth[hit])])
        deep = float(depth[worst])
    return WholePartHit(face=face, followed=followed, depth_mm=deep, worst_cycle=worst,
                        n_cycles=len(hit), cycles=cycle_ranges(hit))
