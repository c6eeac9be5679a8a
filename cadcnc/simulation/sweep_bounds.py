"""A cheap test that a ray cannot meet the material a move removes, before the closed form.

Most rays in a move's box are met by the swept tool only where the earlier moves already cut
(the ball a step back along the pass took the same material), or not at all. The tool swept
from p0 to p1 lies within R of the parallelogram P (:mod:`.tool_sweep`). Seen along the ray's
axis k, P projects to the hull of 4 points in the plane (u, v); for any unit direction n of
that plane, a ray at (u, v) lies at least n . (u, v) - max over the corners of n . corner from
it (a support line). With D the largest of these over 8 directions (along and across the
projected edges), the tool meets the ray only within R of P's extent along k, widened by
sqrt(R^2 - D^2). A ray whose material lies beyond that, by more than MARGIN, is skipped:
the closed form would give nothing to cut, so the stock stays bit-identical.

One row of floats a move (:func:`bounds_table`): 8 x (n_u, n_v, support), then KLO, KHI
(P's extent along k as ray offsets from ``lo[k]``, widened by MARGIN), R2 = R^2 and MISS =
R + MARGIN. Lengths mm.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .tool_sweep import CAPSULE, KIND, ONE, P0, P1, RAD, E

# mm: the closed form's ends can exceed the true ones by round-off amplified by a square
# root (a grazing ray: sqrt(1e-12 mm^2) = 1e-6 mm); a skip keeps 100 times that clear
MARGIN = 1e-4
DIRECTIONS = 8
KLO, KHI, R2, MISS = 3 * DIRECTIONS, 3 * DIRECTIONS + 1, 3 * DIRECTIONS + 2, 3 * DIRECTIONS + 3
BOUNDS = 3 * DIRECTIONS + 4
SHORT = 1e-12   # mm: a projected edge shorter than this gives no direction


@njit(cache=True)
def _directions(row, i, du, dv, cu, cv):
    """Four unit directions from the projected edge (du, dv) (along it and across it, each
    way) with their support over the corners ``cu``, ``cv`` (4,), into ``row[3i:3i + 12]``;
    zeros (no bound) for an edge shorter than SHORT."""
    ln = math.sqrt(du * du + dv * dv)
    if ln <= SHORT:
        return
    du, dv = du / ln, dv / ln
    for j, (nu, nv) in enumerate(((du, dv), (-du, -dv), (-dv, du), (dv, -du))):
        s = -np.inf
        for c in range(4):
            s = max(s, nu * cu[c] + nv * cv[c])
        row[3 * (i + j)], row[3 * (i + j) + 1], row[3 * (i + j) + 2] = nu, nv, s


@njit(cache=True)
def bounds_table(k, lo_k, table):
    """(N, BOUNDS): the module doc's row for rays along axis ``k`` (origin ``lo_k`` mm along
    it) of every move's constants ``table`` (N, CONSTANTS) (:func:`~.tool_sweep.move_table`)."""
    u, v = (k + 1) % 3, (k + 2) % 3
    out = np.zeros((table.shape[0], BOUNDS))
    corners = np.empty((4, 3))
    for m in range(table.shape[0]):
        c = table[m]
        for i in range(3):
            if c[KIND] == CAPSULE:      # the segment ONE: its ends twice
                corners[0, i] = corners[2, i] = c[ONE + i]
                corners[1, i] = corners[3, i] = c[ONE + 3 + i]
            else:
                corners[0, i], corners[1, i] = c[P0 + i], c[P1 + i]
                corners[2, i], corners[3, i] = c[P0 + i] + c[E + i], c[P1 + i] + c[E + i]
        row = out[m]
        cu, cv = corners[:, u].copy(), corners[:, v].copy()
        _directions(row, 0, cu[1] - cu[0], cv[1] - cv[0], cu, cv)
        _directions(row, 4, cu[2] - cu[0], cv[2] - cv[0], cu, cv)
        row[KLO] = corners[:, k].min() - lo_k - MARGIN
        row[KHI] = corners[:, k].max() - lo_k + MARGIN
        row[R2] = c[RAD] * c[RAD]
        row[MISS] = c[RAD] + MARGIN
    return out


@njit(cache=True)
def misses(b, pu, pv, e0, e1):
    """Whether the move of bounds row ``b`` cannot cut the ray at (pu, pv) mm whose material
    lies within [e0, e1] (offsets along it): True means skip it."""
    d = 0.0
    for i in range(DIRECTIONS):
        d = max(d, b[3 * i] * pu + b[3 * i + 1] * pv - b[3 * i + 2])
    return _beyond(b, d, e0, e1)


@njit(cache=True)
def misses_box(b, cu, cv, hu, hv, e0, e1):
    """:func:`misses` for every ray within the rectangle centred at (cu, cv), half sides
    hu, hv (mm), whose material lies within [e0, e1]: the support lines' distance taken
    at the rectangle's nearest corner."""
    d = 0.0
    for i in range(DIRECTIONS):
        nu, nv = b[3 * i], b[3 * i + 1]
        d = max(d, nu * cu + nv * cv - abs(nu) * hu - abs(nv) * hv - b[3 * i + 2])
    return _beyond(b, d, e0, e1)


@njit(cache=True)
def _beyond(b, d, e0, e1):
    """Whether material within [e0, e1] lies beyond the tool of bounds row ``b`` on rays at
    least ``d`` mm from its projected parallelogram (module doc)."""
    if d >= b[MISS]:
        return True
    q = b[R2] - d * d
    g = e0 - b[KHI]
    if g >= 0.0 and g * g >= q:
        return True
    g = b[KLO] - e1
    return g >= 0.0 and g * g >= q
