"""The cut stock against the part, where each ray crosses the part's surface.

At a crossing (t along the ray, c = n . e_k of the outward normal) the stock either holds
the surface point, and the material left is the stock beyond it on the outside, measured
along the ray and times |c| (the thickness across the face; exact on a plane, and rays
are exact along their line); or it does not, and the part has lost material: the stock
resumes |c| times the distance inside. The result is signed: ``left`` > 0 material left,
< 0 material taken (mm). Each patch of surface is sampled by the grid along its normal's
largest component (``dominant``), every ``res^2 / |c|`` mm^2; candidates for a gouge are
refined by the caller with OCCT's exact distance of ``inner`` (the stock's end inside).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange


@njit(cache=True, parallel=True)
def measure(start, t, cos, iv, cnt, left, inner):
    """Fill ``left`` (crossings,) mm (module doc) and ``inner`` (crossings,): the t of the
    stock's end inside the part where the surface is not held (else NaN)."""
    for r in prange(start.shape[0] - 1):
        s, e = start[r], start[r + 1]
        n = cnt[r]
        for j in range(s, e):
            tp = t[j]
            out = 1.0 if cos[j] > 0.0 else -1.0     # the outside lies towards +t or -t
            c = abs(cos[j])
            inner[j] = np.nan
            held = -1
            for i in range(n):
                if iv[r, i, 0] <= tp <= iv[r, i, 1]:
                    held = i
                    break
            if held >= 0:
                if out > 0:
                    along = iv[r, held, 1] - tp
                    if j + 1 < e:
                        along = min(along, t[j + 1] - tp)
                else:
                    along = tp - iv[r, held, 0]
                    if j > s:
                        along = min(along, tp - t[j - 1])
                left[j] = along * c
                continue
            # not held: the nearest stock end on the inside, at most the part's far side
            far = t[j - 1] if (out > 0 and j > s) else (t[j + 1] if (out < 0 and j + 1 < e)
                                                         else tp - out * 1e300)
            end = far
            for i in range(n):
                if out > 0 and iv[r, i, 1] <= tp:
                    end = max(end, iv[r, i, 1])
                elif out < 0 and iv[r, i, 0] >= tp:
                    end = min(end, iv[r, i, 0])
            left[j] = -abs(tp - end) * c
            inner[j] = end


@dataclass
class Samples:
    """The part's surface as the grids sample it: per crossing of a dominant grid, the
    point (n, 3) mm, face (n,), |c| (n,), signed material left (n,) mm, the stock's
    inner end (n, 3) (NaN where the surface is held), and the area (n,) mm^2 it stands for."""

    point: np.ndarray
    face: np.ndarray
    cos: np.ndarray
    left: np.ndarray
    inner: np.ndarray
    area: np.ndarray


def sample_grid(grid, rays) -> Samples:
    """The :class:`Samples` of one :class:`~.grid.Grid` and its part crossings ``rays``
    (start, t, face, cos, dominant) from :func:`~.part_rays.crossings`."""
    start, t, face, cos, dominant = rays
    left, inner = np.empty(len(t)), np.empty(len(t))
    measure(start, t, cos, grid.iv, grid.cnt, left, inner)
    ray = np.repeat(np.arange(len(start) - 1), np.diff(start))
    keep = dominant
    u, v = grid.axes
    pu, pv = grid.ray_points()
    point = np.empty((int(keep.sum()), 3))
    r = ray[keep]
    point[:, u], point[:, v] = pu[r // grid.nv], pv[r % grid.nv]
    point[:, grid.k] = grid.lo[grid.k] + t[keep]
    inner_pt = point.copy()
    inner_pt[:, grid.k] = grid.lo[grid.k] + inner[keep]
    c = np.abs(cos[keep])
    return Samples(point, face[keep], c, left[keep], inner_pt, grid.res ** 2 / c)


def joined(samples: list[Samples]) -> Samples:
    """The samples of every grid as one."""
    return Samples(*(np.concatenate([getattr(s, f) for s in samples])
                     for f in ("point", "face", "cos", "left", "inner", "area")))
