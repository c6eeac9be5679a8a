"""Swept surfaces: linear extrusion and revolution of a basis curve, up to third derivatives.

Mirrors OCCT's ``GeomEvaluator_SurfaceOfExtrusion`` / ``GeomEvaluator_SurfaceOfRevolution``
(Geom_ExtrusionUtils / Geom_RevolutionUtils) over a ``GeomAdaptor_Curve`` of the basis
curve, whose D3 is ``ElCLib`` for lines, circles and ellipses and BSplCLib for B-spline and
Bezier curves (rational included).

Basis curve data: ``cints`` = [curve kind (GeomAbs_CurveType value), degree, periodic,
rational] and ``cbody`` (mm, rad):

    line     O(3) D(3)
    circle   C(3) X(3) Y(3) R
    ellipse  C(3) X(3) Y(3) a(major) b(minor)
    B-spline / Bezier   first last (the adaptor's bounds) knot_first knot_last O(3)

B-spline and Bezier curves take their knots from ``knots`` (flat), poles from
``poles[:, 0, :]`` (n, 3; pole - O) and weights from ``weights[:, 0]``.

Extrusion body: D(3) (unit direction), then the curve body; P(u, v) = C(u) + v D.
Revolution body: L(3) D(3) (axis point and unit direction), then the curve body; P(u, v)
is C(v) turned by the angle u about the axis.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .bspline import curve_derivatives, normalize_periodic

_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)

LINE, CIRCLE, ELLIPSE, BEZIER_CURVE, BSPLINE_CURVE = 0, 1, 2, 5, 6
"""Curve kinds: OCCT's GeomAbs_CurveType values."""
UNSUPPORTED = 1
"""Status of a basis curve kind not handled here (0: evaluated)."""
_SQUARE_CONFUSION = 1e-14  # Precision::SquareConfusion(), mm^2
CURVE_ROWS = 4
"""Rows of the curve scratch: C, C', C'', C'''."""


@_jit
def curve(cints: np.ndarray, cbody: np.ndarray, knots: np.ndarray, poles: np.ndarray,
          weights: np.ndarray, t: float, order: int, work: np.ndarray,
          cout: np.ndarray) -> int:
    """C(t) and derivatives up to ``order`` (<= 3) into cout rows 0..order (rows above
    zeroed); 0, or UNSUPPORTED for another curve kind."""
    kind = cints[0]
    if kind == LINE:
        for i in range(3):
            cout[0, i] = cbody[i] + t * cbody[3 + i]
            cout[1, i] = cbody[3 + i]
            cout[2, i] = 0.0
            cout[3, i] = 0.0
        return 0
    if kind == CIRCLE or kind == ELLIPSE:
        a = cbody[9]
        b = cbody[10] if kind == ELLIPSE else a
        xc = a * math.cos(t)
        yc = b * math.sin(t)
        xs = a * math.sin(t)
        yc2 = b * math.cos(t)
        for i in range(3):
            x = cbody[3 + i]
            y = cbody[6 + i]
            cout[0, i] = cbody[i] + xc * x + yc * y
            cout[1, i] = -xs * x + yc2 * y
            cout[2, i] = -xc * x - yc * y
            cout[3, i] = xs * x - yc2 * y
        return 0
    if kind == BSPLINE_CURVE or kind == BEZIER_CURVE:
        p = cints[1]
        periodic = cints[2] != 0
        side = 1 if t == cbody[0] else (-1 if t == cbody[1] else 0)
        if periodic:
            t = normalize_periodic(t, cbody[2], cbody[3])
        curve_derivatives(knots, poles, weights, p, periodic, cints[3] != 0, t, side,
                          order, work, cout)
        for i in range(3):  # the poles are stored relative to cbody[4:7]
            cout[0, i] += cbody[4 + i]
        for r in range(order + 1, CURVE_ROWS):
            for i in range(3):
                cout[r, i] = 0.0
        return 0
    return UNSUPPORTED


@_jit
def extrusion(ints: np.ndarray, body: np.ndarray, knots: np.ndarray, poles: np.ndarray,
              weights: np.ndarray, u: float, v: float, order: int, work: np.ndarray,
              out: np.ndarray) -> int:
    """P = C(u) + v D into out (D3 layout rows); 0, or UNSUPPORTED."""
    cout = work[:3 * CURVE_ROWS].reshape((CURVE_ROWS, 3))
    status = curve(ints, body[3:], knots, poles, weights, u, order, work[3 * CURVE_ROWS:],
                   cout)
    if status != 0:
        return status
    last = 10 if order >= 3 else 6
    for r in range(last):
        for i in range(3):
            out[r, i] = 0.0
    for i in range(3):
        out[0, i] = cout[0, i] + v * body[i]
        out[1, i] = cout[1, i]
        out[2, i] = body[i]
        out[3, i] = cout[2, i]
        if order >= 3:
            out[6, i] = cout[3, i]
    return 0


_TURNS = ((0, 0), (0, 1), (1, 0), (0, 2), (1, 1), (2, 0), (0, 3), (1, 2), (2, 1), (3, 0))
"""Per output row (D3 layout): (curve derivative turned, order of its u-derivative)."""


@_jit
def revolution(ints: np.ndarray, body: np.ndarray, knots: np.ndarray, poles: np.ndarray,
               weights: np.ndarray, u: float, v: float, order: int, work: np.ndarray,
               out: np.ndarray) -> int:
    """P = C(v) turned by u about the axis (L, D) into out; 0, or UNSUPPORTED.

    With s the part of x across the axis, the turned x is x + (cos u - 1) s + sin u (D x s)
    (Geom_RevolutionUtils); its k-th u-derivative is a s + b (D x s) with (a, b) =
    (-sin, cos), (-cos, -sin), (sin, -cos) for k = 1, 2, 3. The point's s comes from
    C(v) - L, the curve derivatives' from themselves; r_v, r_vv, r_vvv are the turned
    first, second and third curve derivatives."""
    cout = work[:3 * CURVE_ROWS].reshape((CURVE_ROWS, 3))
    status = curve(ints, body[6:], knots, poles, weights, v, order, work[3 * CURVE_ROWS:],
                   cout)
    if status != 0:
        return status
    c = math.cos(u)
    s = math.sin(u)
    cos_k = (c - 1.0, -s, -c, s)
    sin_k = (s, c, -s, -c)
    rows = 10 if order >= 3 else 6
    for r in range(rows):
        j, k = _TURNS[r]
        x = cout[j, 0] - (body[0] if j == 0 else 0.0)
        y = cout[j, 1] - (body[1] if j == 0 else 0.0)
        z = cout[j, 2] - (body[2] if j == 0 else 0.0)
        d = x * body[3] + y * body[4] + z * body[5]
        x -= d * body[3]
        y -= d * body[4]
        z -= d * body[5]
        a = cos_k[k]
        b = sin_k[k]
        base = 1.0 if k == 0 else 0.0  # the turned vector itself, not a u-derivative
        out[r, 0] = base * cout[j, 0] + a * x + b * (body[4] * z - body[5] * y)
        out[r, 1] = base * cout[j, 1] + a * y + b * (body[5] * x - body[3] * z)
        out[r, 2] = base * cout[j, 2] + a * z + b * (body[3] * y - body[4] * x)
    # OCCT 7.9 sets r_u (and r_uuu) to zero where the curve is within 1e-7 mm of the axis
    if out[1, 0] ** 2 + out[1, 1] ** 2 + out[1, 2] ** 2 < _SQUARE_CONFUSION:
        for r in range(1, rows, 5):  # rows 1 and 6
            for i in range(3):
                out[r, i] = 0.0
    return 0
