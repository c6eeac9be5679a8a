"""Elementary surfaces (plane, cylinder, cone, sphere, torus) up to third derivatives.

Mirrors OCCT's ``ElSLib`` D0..D3 (what ``Geom_Plane``, ``Geom_CylindricalSurface``, ...
``::D2`` call). ``body`` is the float parameter vector: the placement (OCCT's gp_Ax3)
origin O, XDirection X, YDirection Y, Direction Z at body[0:12] (mm, unit vectors; the
frame may be left-handed), then the radii (mm) and the cone's semi-angle (rad):

    plane    O X Y Z                 P = O + u X + v Y
    cylinder O X Y Z R               P = O + R (cos u X + sin u Y) + v Z
    cone     O X Y Z R alpha         P = O + (R + v sin a)(cos u X + sin u Y) + v cos a Z
    sphere   O X Y Z R               P = O + R cos v (cos u X + sin u Y) + R sin v Z
    torus    O X Y Z R r             P = O + (R + r cos v)(cos u X + sin u Y) + r sin v Z

Every derivative is a X + b Y + c Z: ``elementary`` writes those coefficients, one row of
``coef`` ((10, 3) scratch) per output row, then combines them with the frame.
"""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
_EPS = 2.220446049250313e-16  # RealEpsilon()
PLANE, CYLINDER, CONE, SPHERE, TORUS = 0, 1, 2, 3, 4
"""OCCT's GeomAbs_SurfaceType values of the elementary kinds."""


@_jit
def elementary(kind: int, body: np.ndarray, u: float, v: float, order: int,
               coef: np.ndarray, out: np.ndarray) -> None:
    """Rows r, r_u, r_v, r_uu, r_uv, r_vv (and for order 3 r_uuu, r_uuv, r_uvv, r_vvv)
    of an elementary surface into out; coef is (10, 3) scratch."""
    def put(r, a, b, c):  # an inner function: compiled into this one (no call per row)
        coef[r, 0] = a
        coef[r, 1] = b
        coef[r, 2] = c

    rows = 10 if order >= 3 else 6
    coef[:] = 0.0
    cu = math.cos(u)
    su = math.sin(u)
    if kind == PLANE:
        put(0, u, v, 0.0)
        put(1, 1.0, 0.0, 0.0)
        put(2, 0.0, 1.0, 0.0)
    elif kind == CYLINDER:
        a1 = body[12] * math.cos(u)
        a2 = body[12] * math.sin(u)
        put(0, a1, a2, v)
        put(1, -a2, a1, 0.0)
        put(2, 0.0, 0.0, 1.0)
        put(3, -a1, -a2, 0.0)
        put(6, a2, -a1, 0.0)
    elif kind == CONE:
        ca = math.cos(body[13])
        sa = math.sin(body[13])
        r = body[12] + v * sa
        a1 = r * cu
        a2 = r * su
        r1 = sa * cu
        r2 = sa * su
        put(0, a1, a2, v * ca)
        put(1, -a2, a1, 0.0)
        put(2, r1, r2, ca)
        put(3, -a1, -a2, 0.0)
        put(4, -r2, r1, 0.0)
        put(6, a2, -a1, 0.0)
        put(7, -r1, -r2, 0.0)
    else:  # sphere (no major radius) and torus: (R + r1)(cu X + su Y) + r2 Z
        minor = body[13] if kind == TORUS else body[12]
        major = body[12] if kind == TORUS else 0.0
        r1 = minor * math.cos(v)
        r2 = minor * math.sin(v)
        # ElSLib::TorusD* zero the products below this (OCC620); SphereD* do not
        eps = 10.0 * (major + minor) * _EPS if kind == TORUS else -1.0
        a1 = _cut((major + r1) * cu, eps)
        a2 = _cut((major + r1) * su, eps)
        a3 = _cut(r2 * cu, eps)
        a4 = _cut(r2 * su, eps)
        a5 = _cut(r1 * cu, eps)
        a6 = _cut(r1 * su, eps)
        put(0, a1, a2, r2)
        put(1, -a2, a1, 0.0)
        put(2, -a3, -a4, r1)
        put(3, -a1, -a2, 0.0)
        put(4, a4, -a3, 0.0)
        put(5, -a5, -a6, -r2)
        put(6, a2, -a1, 0.0)
        put(7, a3, a4, 0.0)
        put(8, a6, -a5, 0.0)
        put(9, a3, a4, -r1)
    for r in range(rows):
        for i in range(3):
            out[r, i] = (coef[r, 0] * body[3 + i] + coef[r, 1] * body[6 + i]
                         + coef[r, 2] * body[9 + i])
    for i in range(3):
        out[0, i] += body[i]


@_jit
def _cut(x: float, eps: float) -> float:
    return 0.0 if abs(x) <= eps else x
