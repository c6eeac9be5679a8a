"""Compiled surface evaluators: r(u, w) and its partial derivatives as OCCT computes them.

``d2`` mirrors what ``BRepAdaptor_Surface::D2`` returns for a face (``FaceSurface``'s hot
path): the face's ``Geom_Surface`` D2 (Geom_Plane, Geom_CylindricalSurface,
Geom_ConicalSurface, Geom_SphericalSurface, Geom_ToroidalSurface, Geom_BSplineSurface,
Geom_BezierSurface, Geom_SurfaceOfLinearExtrusion, Geom_SurfaceOfRevolution,
Geom_OffsetSurface, evaluated as GeomAdaptor_Surface does) in the surface's own frame, then
the face's TopLoc_Location applied to the point and the five vectors. Numbers only:
``cadcnc.geometry.surface_data`` extracts them from a face. No OCCT here.

Arguments (float64 / int64 numpy arrays, C-contiguous; lengths mm, angles rad):

- ``kind``: OCCT's GeomAbs_SurfaceType value (PLANE ... OFFSET below).
- ``params`` (m,): [0:12] the location x -> M x + T as M row-major (9) then T (3);
  [12:16] the face's parameter box umin, umax, wmin, wmax (BRepTools::UVBounds; OCCT's
  B-spline evaluation picks knot spans by it); [16:] the kind's body (analytic.py,
  swept.py; B-spline/Bezier: u_first, u_last, w_first, w_last of the knot range, then
  the origin O the poles are given from; offset: the distance, then the basis's body).
- ``ints`` (k,): [0] 1 when the location is not the identity; [1:] the kind's integers
  (B-spline/Bezier: p, q, periodic_u, periodic_w, rational; swept: see swept.py; offset:
  the basis kind, then its integers).
- ``knots_u``, ``knots_v`` (flat knots, multiplicities expanded), ``poles`` (n_u, n_v, 3;
  each pole minus O), ``weights`` (n_u, n_v): B-spline/Bezier surface data, or the swept
  basis curve's in knots_u / poles[:, 0] / weights[:, 0]; empty arrays of those ranks
  otherwise.
- ``work`` (WORK_SIZE,) float64 scratch owned by the caller (``new_work()``).
- ``out`` (6, 3): filled with r, r_u, r_w, r_uu, r_uw, r_ww (``d3``: (10, 3), then
  r_uuu, r_uuw, r_uww, r_www).

Every function returns a status: OK, UNSUPPORTED (kind or basis curve not handled: ask
OCCT) or SINGULAR (offset surface where the basis normal vanishes: OCCT then uses an
osculating surface or fails). Nothing allocates: callable from Python and from other
``numba.njit`` code::

    data = surface_data(face)                 # cadcnc.geometry.surface_data; None: use OCCT
    work, out = new_work(), np.zeros((6, 3))
    status = d2(*data.args, u, w, work, out)  # data.args = (kind, params, ..., weights)

Compiled code is cached (``cache=True``) in this folder's __pycache__; numba does not see
edits to a function another module calls, so the package drops the cache when any of its
sources changes (:mod:`cadcnc.interp.kernel`). A first compilation takes 10-20 s, a
cached load well under 1 s.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .analytic import elementary
from .bspline import BASIS_SCRATCH, MAX_DEGREE, near_knot, normalize_periodic, surface_derivatives
from .swept import UNSUPPORTED, extrusion, revolution

_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
_inline = numba.njit(cache=True, nogil=True, error_model="numpy", inline="always", _nrt=False)

PLANE, CYLINDER, CONE, SPHERE, TORUS = 0, 1, 2, 3, 4
BEZIER, BSPLINE, REVOLUTION, EXTRUSION, OFFSET = 5, 6, 7, 8, 9
"""Surface kinds: OCCT's GeomAbs_SurfaceType values."""
OK, SINGULAR = 0, 2
"""d2's statuses: evaluated (OK), kind or basis curve not handled (UNSUPPORTED, 1), offset
surface whose basis normal vanishes (SINGULAR)."""
HEADER = 16
"""Length of the params header (location 12, parameter box 4) before the kind's body."""
WORK_SIZE = 2048
"""Floats of scratch ``work`` must hold: enough for degree <= MAX_DEGREE and an offset."""
_OFFSET_ROWS = 30           # the basis surface's D3 (10 x 3) at the start of work
_D1_MAGNITUDE_TOL = 1e-9    # Geom_OffsetSurfaceUtils: |normal| at or below this is singular

# the deepest use: an offset's B-spline basis (two basis tables, sums, basis scratch)
assert WORK_SIZE >= _OFFSET_ROWS + 8 * (MAX_DEGREE + 1) + 80 + BASIS_SCRATCH


def new_work() -> np.ndarray:
    """A scratch array for the evaluators, (WORK_SIZE,) float64 (one per thread)."""
    return np.zeros(WORK_SIZE)


@_inline
def _bspline(bints: np.ndarray, body: np.ndarray, box: np.ndarray, knots_u: np.ndarray,
             knots_v: np.ndarray, poles: np.ndarray, weights: np.ndarray, u: float,
             v: float, order: int, work: np.ndarray, out: np.ndarray, bezier: bool) -> None:
    """B-spline / Bezier surface with GeomAdaptor_Surface's choice of spans at the box."""
    p = bints[0]
    q = bints[1]
    per_u = bints[2] != 0
    per_v = bints[3] != 0
    side_u = 1 if u == box[0] else (-1 if u == box[1] else 0)
    side_v = 1 if v == box[2] else (-1 if v == box[3] else 0)
    if per_u:
        u = normalize_periodic(u, body[0], body[1])
    if per_v:
        v = normalize_periodic(v, body[2], body[3])
    if bezier or (side_u == 0 and side_v == 0) or not (
            near_knot(knots_u, p, u) or near_knot(knots_v, q, v)):
        side_u = 0  # the cached span evaluation
        side_v = 0
    else:  # LocalD2: a parameter on a knot takes the span inside the box
        side_u = -1 if side_u == -1 else 1
        side_v = -1 if side_v == -1 else 1
    surface_derivatives(knots_u, knots_v, poles, weights, p, q, per_u, per_v, bints[4] != 0,
                        u, v, side_u, side_v, order, work, out)
    for i in range(3):  # the poles are stored relative to body[4:7]
        out[0, i] += body[4 + i]


@_inline
def _basis(kind: int, body: np.ndarray, bints: np.ndarray, box: np.ndarray,
           knots_u: np.ndarray, knots_v: np.ndarray, poles: np.ndarray, weights: np.ndarray,
           u: float, v: float, order: int, work: np.ndarray, out: np.ndarray) -> int:
    """Every kind but the offset, in the surface's own frame, up to ``order`` (2 or 3)."""
    if PLANE <= kind <= TORUS:
        elementary(kind, body, u, v, order, work[:_OFFSET_ROWS].reshape((10, 3)), out)
    elif kind == BSPLINE or kind == BEZIER:
        _bspline(bints, body, box, knots_u, knots_v, poles, weights, u, v, order, work, out,
                 kind == BEZIER)
    elif kind == EXTRUSION:
        return extrusion(bints, body, knots_u, poles, weights, u, v, order, work, out)
    elif kind == REVOLUTION:
        return revolution(bints, body, knots_u, poles, weights, u, v, order, work, out)
    else:
        return UNSUPPORTED
    return OK


_NORMAL_TERMS = (
    (0, 1, 1, 2),                              # n    = S_u x S_v
    (1, 1, 3, 2), (1, 1, 1, 4),                # n_u  = S_uu x S_v + S_u x S_uv
    (2, 1, 4, 2), (2, 1, 1, 5),                # n_v  = S_uv x S_v + S_u x S_vv
    (3, 1, 6, 2), (3, 2, 3, 4), (3, 1, 1, 7),  # n_uu = S_uuu x S_v + 2 S_uu x S_uv + S_u x S_uuv
    (4, 1, 7, 2), (4, 1, 3, 5), (4, 1, 1, 8),  # n_uv = S_uuv x S_v + S_uu x S_vv + S_u x S_uvv
    (5, 1, 8, 2), (5, 2, 4, 5), (5, 1, 1, 9),  # n_vv = S_uvv x S_v + 2 S_uv x S_vv + S_u x S_vvv
)
"""(row of n, factor, i, j): n's derivatives as sums of factor * S_i x S_j (D3 rows)."""


@_jit
def _offset(body: np.ndarray, bints: np.ndarray, box: np.ndarray, knots_u: np.ndarray,
            knots_v: np.ndarray, poles: np.ndarray, weights: np.ndarray, u: float, v: float,
            work: np.ndarray, out: np.ndarray) -> int:
    """r = S + d N, N = n / |n|, n = S_u x S_v, differentiated twice (needs S's D3).

    With m = |n|: N_u = (n_u - N m_u) / m, m_u = N . n_u, m_uv = N_v . n_u + N . n_uv and
    N_uv = (n_uv - N_u m_v - N_v m_u - N m_uv) / m (likewise for uu, vv)."""
    def _dot(a, i, b, j):  # an inner function: compiled inline, no call per literal index
        return a[i, 0] * b[j, 0] + a[i, 1] * b[j, 1] + a[i, 2] * b[j, 2]

    s = work[:_OFFSET_ROWS].reshape((10, 3))
    status = _basis(bints[0], body[1:], bints[1:], box, knots_u, knots_v, poles, weights, u,
                    v, np.int64(3), work[_OFFSET_ROWS:], s)
    if status != OK:
        return status
    # OCCT's singularity test: derivatives longer than 1 normalised, then |cross| <= tol
    lu = max(1.0, math.sqrt(_dot(s, 1, s, 1)))
    lv = max(1.0, math.sqrt(_dot(s, 2, s, 2)))
    x = s[1, 1] * s[2, 2] - s[1, 2] * s[2, 1]
    y = s[1, 2] * s[2, 0] - s[1, 0] * s[2, 2]
    z = s[1, 0] * s[2, 1] - s[1, 1] * s[2, 0]
    if (x * x + y * y + z * z) / (lu * lu * lv * lv) <= _D1_MAGNITUDE_TOL ** 2:
        return SINGULAR
    n = out  # n and its derivatives (rows 0..5) until the last loop overwrites them
    n[:] = 0.0
    for t in range(len(_NORMAL_TERMS)):
        r, f, i, j = _NORMAL_TERMS[t]
        n[r, 0] += f * (s[i, 1] * s[j, 2] - s[i, 2] * s[j, 1])
        n[r, 1] += f * (s[i, 2] * s[j, 0] - s[i, 0] * s[j, 2])
        n[r, 2] += f * (s[i, 0] * s[j, 1] - s[i, 1] * s[j, 0])
    m = math.sqrt(_dot(n, 0, n, 0))
    e = work[_OFFSET_ROWS:_OFFSET_ROWS + 9].reshape((3, 3))  # N, N_u, N_v
    for i in range(3):
        e[0, i] = n[0, i] / m
    mu = _dot(e, 0, n, 1)
    mv = _dot(e, 0, n, 2)
    for i in range(3):
        e[1, i] = (n[1, i] - e[0, i] * mu) / m
        e[2, i] = (n[2, i] - e[0, i] * mv) / m
    muu = _dot(e, 1, n, 1) + _dot(e, 0, n, 3)
    muv = _dot(e, 2, n, 1) + _dot(e, 0, n, 4)
    mvv = _dot(e, 2, n, 2) + _dot(e, 0, n, 5)
    d = body[0]
    for i in range(3):
        nuu = (n[3, i] - 2.0 * e[1, i] * mu - e[0, i] * muu) / m
        nuv = (n[4, i] - e[1, i] * mv - e[2, i] * mu - e[0, i] * muv) / m
        nvv = (n[5, i] - 2.0 * e[2, i] * mv - e[0, i] * mvv) / m
        out[0, i] = s[0, i] + d * e[0, i]
        out[1, i] = s[1, i] + d * e[1, i]
        out[2, i] = s[2, i] + d * e[2, i]
        out[3, i] = s[3, i] + d * nuu
        out[4, i] = s[4, i] + d * nuv
        out[5, i] = s[5, i] + d * nvv
    return OK


@_inline
def _locate(params: np.ndarray, ints: np.ndarray, rows: int, out: np.ndarray) -> None:
    """Apply the face's location: point row 0 -> M r + T, vector rows -> M v."""
    if ints[0] == 0:
        return
    for r in range(rows):
        x = out[r, 0]
        y = out[r, 1]
        z = out[r, 2]
        for i in range(3):
            out[r, i] = params[3 * i] * x + params[3 * i + 1] * y + params[3 * i + 2] * z
            if r == 0:
                out[r, i] += params[9 + i]


@_jit
def d2(kind: int, params: np.ndarray, ints: np.ndarray, knots_u: np.ndarray,
       knots_v: np.ndarray, poles: np.ndarray, weights: np.ndarray, u: float, w: float,
       work: np.ndarray, out: np.ndarray) -> int:
    """Fill out (6, 3) with r, r_u, r_w, r_uu, r_uw, r_ww at (u, w) as
    BRepAdaptor_Surface::D2 does (mm per parameter unit to the power of the order);
    returns OK, UNSUPPORTED or SINGULAR."""
    box = params[12:HEADER]
    if kind == OFFSET:
        status = _offset(params[HEADER:], ints[1:], box, knots_u, knots_v, poles, weights, u,
                         w, work, out)
    else:
        status = _basis(kind, params[HEADER:], ints[1:], box, knots_u, knots_v, poles,
                        weights, u, w, np.int64(2), work, out)
    if status == OK:
        _locate(params, ints, np.int64(6), out)
    return status


@_jit
def d3(kind: int, params: np.ndarray, ints: np.ndarray, knots_u: np.ndarray,
       knots_v: np.ndarray, poles: np.ndarray, weights: np.ndarray, u: float, w: float,
       work: np.ndarray, out: np.ndarray) -> int:
    """As ``d2`` with out (10, 3): rows 6..9 r_uuu, r_uuw, r_uww, r_www (OCCT's D3 returns
    them as D3U, D3V, D3UUV, D3UVV). Offset surfaces are UNSUPPORTED here."""
    if kind == OFFSET:
        return UNSUPPORTED
    status = _basis(kind, params[HEADER:], ints[1:], params[12:HEADER], knots_u, knots_v,
                    poles, weights, u, w, np.int64(3), work, out)
    if status == OK:
        _locate(params, ints, np.int64(10), out)
    return status
