"""Where waterline finishing's levels go: from the top of the selected faces to their bottom.

The ball centre runs on horizontal planes z = const. Over samples p of the selected faces
(outward normal N) the centres p + R' N range from ``lo`` to ``hi`` in z; ``hi`` is made
exact where the top is a horizontal face or a horizontal tangency (:func:`critical_heights`).

- **Fixed** (``--stepdown D``): levels hi, hi - D, hi - 2D, ... down to lo.
- **Scallop** (``--scallop H``): each next level as far below the last as every sample
  between them allows, the first half that below hi. Across the loops (down the slope)
  two neighbouring centres a chord c apart on the offset surface leave a cusp H high
  (:func:`~cadcnc.ops.finish.plan.centre_chord`, the surface's normal curvature k taken
  down the slope), and on a face sloping at phi from horizontal the levels are
  ``Delta z = c sin phi = c sqrt(1 - N_z^2)`` apart, phi the gentlest between the two
  levels on the sample's cross-section (:mod:`.slope`): the raster planes' rule with the
  planes' normal +Z (:func:`~cadcnc.ops.finish.plan.across`). A vertical wall takes
  the full chord; a near-flat area (within ``FLAT_DEG`` of horizontal) is left to raster
  (``flat``).

**Critical heights.** A level within ``CRITICAL_MM`` (1e-9 mm) of the offset of a
horizontal face (z of the plane + R'), of a horizontal tangency (a point where N = +Z:
the top of a dome, the foot of a fillet; found by Gauss-Newton on N_x = N_y = 0 from the
near-flat samples), or of hi or lo, would cut the offset surface where it is tangent to
the plane: its section is a point, a curve of zero width or a face. Such a level moves by
half a stepdown (half the spacing there with ``--scallop``): down, or up at the bottom.
Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...core.errors import InputError
from ...core.tolerances import VERTICAL
from ...core.work_limits import MAX_PLANES, refuse_over
from .plan import DOWN_NZ, FaceSamples, across, adaptive_offsets, centre_chord, planes_estimate
from .polish import face_derivatives
from .slope import strip_pairs

FLAT_DEG = 5.0
"""deg: a sample whose normal is within this of +Z is flat: left to raster."""
CRITICAL_MM = 1e-9
"""mm: a level this near a critical height is moved onto it (module doc)."""
TOP_MM = 1e-3
"""mm per mm of R' (at least 1): a critical height this near the highest reachable
centre height is the top the levels start from."""
TANGENCY_DEG = 10.0
"""deg: samples this near flat start the search for horizontal tangencies."""
MAX_STARTS = 200   # per face: tangency searches
START_MM = 2.0     # mm: one tangency search per square of this side (its flattest sample)
Z = np.array([0.0, 0.0, 1.0])


@dataclass
class LevelPlan:
    """The levels of one waterline operation: ``offsets`` (L,) z descending (mm), their
    plane ``normal`` (+Z); per sample its centre height ``f`` (N,) and ``reason`` (N,)
    ("" served, "unreachable", "too tight", "flat"); ``moved``: sentences of the levels
    moved off a critical height; ``flat_area`` mm^2 left to raster."""

    offsets: np.ndarray
    normal: np.ndarray
    f: np.ndarray
    reason: np.ndarray
    moved: list[str] = field(default_factory=list)
    flat_area: float = 0.0
    spacing: np.ndarray = field(default_factory=lambda: np.zeros(0))


def sample_reasons(samples: FaceSamples, k, g, offset: float) -> np.ndarray:
    """(N,) why the levels cannot serve each sample ("" when they can)."""
    reason = np.full(len(samples), "", dtype=object)
    reason[g < math.sin(math.radians(FLAT_DEG))] = "flat"
    reason[k * offset >= 1.0] = "too tight"
    reason[samples.normals[:, 2] < DOWN_NZ] = "unreachable"
    return reason


def _tangencies(surface, uv: np.ndarray, iterations: int = 12) -> list[tuple[float, float]]:
    """(u, w) of the points where the face's normal is vertical, found from the starts
    ``uv`` (M, 2): Newton on N_x = N_y = 0 for all starts at once, the Jacobian of N from
    the compiled second derivatives (Weingarten); a start that leaves the parameter box
    is dropped, one that converges outside the trims too."""
    uv = np.array(uv, dtype=float).reshape(-1, 2)
    (u0, u1), (w0, w1) = surface.u_range, surface.w_range
    live = np.ones(len(uv), bool)
    done = np.zeros(len(uv), bool)
    for it in range(iterations + 1):
        act = np.flatnonzero(live & ~done)
        if not len(act):
            break
        d = face_derivatives(surface, uv[act])
        ru, rw, ruu, ruw, rww = (d[:, k] for k in range(1, 6))
        m = np.cross(ru, rw)
        mn = np.linalg.norm(m, axis=1)[:, None]
        mh = m / mn
        nxy = surface.normal_sign * mh[:, :2]
        small = np.hypot(nxy[:, 0], nxy[:, 1])
        done[act[small < 1e-13]] = True   # |n_xy|: horizontal to round-off
        if it == iterations:
            done[act[small < 1e-10]] = True   # last iteration: as close as Newton gets
            break
        cols = []
        for dm in (np.cross(ruu, rw) + np.cross(ru, ruw), np.cross(ruw, rw) + np.cross(ru, rww)):
            cols.append(surface.normal_sign * (dm - mh * np.einsum("ij,ij->i", mh, dm)[:, None])
                        / mn)
        a, b, c, e = cols[0][:, 0], cols[1][:, 0], cols[0][:, 1], cols[1][:, 1]
        det = a * e - b * c
        ok = np.abs(det) > 1e-300   # no / 0
        det = np.where(ok, det, 1.0)
        du = -(e * nxy[:, 0] - b * nxy[:, 1]) / det
        dw = -(a * nxy[:, 1] - c * nxy[:, 0]) / det
        step = ~done[act] & ok
        uv[act[step], 0] += du[step]
        uv[act[step], 1] += dw[step]
        live[act[~ok]] = False
        out_u = ((uv[:, 0] < u0) | (uv[:, 0] > u1)) & (surface.u_period is None)
        out_w = ((uv[:, 1] < w0) | (uv[:, 1] > w1)) & (surface.w_period is None)
        live &= ~(out_u | out_w)
    return [(float(u), float(w)) for u, w in uv[live & done] if surface.contains(u, w)]


def critical_heights(part, faces, samples: FaceSamples, offset: float) -> list[tuple[float, str]]:
    """(z, what) of the centre heights (mm) where a level would be tangent to the offset
    of a selected face (module doc), ``offset`` = R'."""
    out = []
    for n in faces:
        s = part.face(n)
        mine = np.nonzero(samples.faces == n)[0]
        if s.kind == "plane":
            nz = samples.normals[mine, 2]
            if len(mine) and np.all(np.abs(nz) > 1.0 - VERTICAL):
                z = float(np.mean(samples.points[mine, 2]) + offset * np.sign(nz[0]))
                out.append((z, f"face {n}, horizontal, offset"))
            continue
        near = mine[samples.normals[mine, 2] > math.cos(math.radians(TANGENCY_DEG))]
        near = near[np.argsort(-samples.normals[near, 2])]   # the flattest first
        cells = np.floor(samples.points[near, :2] / START_MM).astype(np.int64)
        _, first = np.unique(cells, axis=0, return_index=True)   # the flattest per cell
        starts = near[np.sort(first)][:MAX_STARTS]
        uv = np.array([s.project(samples.points[i])[:2] for i in starts]).reshape(-1, 2)
        for found in _tangencies(s, uv):
            c = s.point(*found) + offset * s.normal(*found)
            if not any(abs(c[2] - z) < CRITICAL_MM for z, _ in out):
                out.append((float(c[2]), f"face {n}, horizontal tangency at "
                            f"({c[0]:.3f}, {c[1]:.3f})"))
    return out


def plan_levels(samples: FaceSamples, radius: float, allowance: float, *,
                stepdown: float | None = None, scallop: float | None = None,
                critical=(), max_levels: int = MAX_PLANES, work: dict | None = None
                ) -> LevelPlan:
    """The levels over ``samples`` (module doc), ``critical`` the (z, what) of
    :func:`critical_heights`. Their number is estimated before any is placed and
    refused over ``max_levels`` (:class:`~cadcnc.core.work_limits.WorkLimitError`); ``work``: a dict
    given ``planes_estimate``."""
    work = {} if work is None else work
    r1 = radius + allowance
    k, g = across(samples, Z)
    f = samples.points[:, 2] + r1 * samples.normals[:, 2]
    reason = sample_reasons(samples, k, g, r1)
    flat_area = float(samples.areas[reason == "flat"].sum())
    reach = reason != "unreachable"
    if not reach.any():
        return LevelPlan(np.zeros(0), Z.copy(), f, reason)
    lo, hi = float(f[reach].min()), float(f[reach].max())
    tops = [z for z, _ in critical if abs(z - hi) < TOP_MM * max(1.0, r1)]
    hi = max(tops) if tops else hi
    spacing = np.zeros(0)
    if stepdown is not None:
        count = work["planes_estimate"] = planes_estimate(lo, hi, stepover=stepdown) + 1
        refuse_over(f"waterline levels over {hi - lo:.4g} mm (R' {r1:g} mm) at a stepdown "
                    f"of {stepdown:g} mm", count, max_levels, "levels",
                    "give a larger --stepdown")
        steps = int(math.floor((hi - lo) / stepdown + 1e-12))   # floor's round-off
        levels = hi - stepdown * np.arange(steps + 1)
        half = np.full(len(levels), 0.5 * stepdown)
    else:
        c, serve = centre_chord(scallop, k, radius, allowance), reason == ""
        spacing = np.where(serve, c * g, np.inf)
        q = samples.points + r1 * samples.normals
        pairs, bound = strip_pairs(samples, q, -f, Z, k, g, c, serve, r1)   # (.slope)
        estimate = work["planes_estimate"] = planes_estimate(-hi, -lo, f=-f, spacing=bound)
        refuse_over(f"waterline levels over {hi - lo:.4g} mm (R' {r1:g} mm) for a scallop "
                    f"of {scallop:g} mm", estimate, max_levels, "levels",
                    "give a larger --scallop")
        levels = -adaptive_offsets(-f, spacing, -hi, -lo, limit=int(1.5 * estimate) + 2,
                                   pairs=pairs)
        gaps = np.abs(np.diff(levels))
        half = 0.5 * (np.r_[gaps, gaps[-1:]] if len(gaps) else np.full(1, hi - lo))
    marks = list(critical) + [(hi, "the top of the faces"), (lo, "the bottom of the faces")]
    moved = []
    for i, z in enumerate(levels):
        hit = next((what for zc, what in marks if abs(z - zc) <= CRITICAL_MM), None)
        if hit is None:
            continue
        to = z - half[i] if z - half[i] >= lo else z + half[i]
        moved.append(f"level z {z:.6g} mm moved to {to:.6g} mm: at {hit}")
        levels[i] = to
    levels = np.array(sorted(set(levels.tolist()), reverse=True))
    return LevelPlan(levels, Z.copy(), f, reason, moved, flat_area, spacing)


def check_stepdown(stepdown: float | None, radius: float) -> None:
    """InputError for a stepdown over the ball's diameter (no cusp is bounded above it)."""
    if stepdown is not None and stepdown > 2.0 * radius:
        raise InputError(f"stepdown {stepdown:g} mm is over the ball's diameter "
                         f"{2 * radius:g} mm: levels that far apart leave the wall between "
                         "them uncut; give --stepdown <= 2R")
