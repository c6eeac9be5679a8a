"""Differential geometry of a parametric surface at one point, from its derivatives.

Kernel-free: takes the partial derivatives r_u, r_w, r_uu, r_uw, r_ww ((3,) float arrays, mm)
and the unit normal n that points out of the material, and returns fundamental forms and
curvatures. Curvature sign convention (docs/method.md): second fundamental form taken
against n, so k < 0 where the surface bends away from the cutter (convex seen from outside)
and k > 0 where it bends towards it (concave). Curvatures are in 1/mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class FundamentalForms:
    """First (E, F, G; mm^2) and second (L, M, N; mm) fundamental form coefficients."""

    E: float
    F: float
    G: float
    L: float
    M: float
    N: float


@dataclass(frozen=True)
class PrincipalCurvatures:
    """k_max >= k_min (1/mm) and their unit 3-D directions ((3,) arrays)."""

    k_max: float
    k_min: float
    d_max: np.ndarray
    d_min: np.ndarray


def cross(a, b) -> np.ndarray:
    """a x b of two (3,) float vectors, (3,): np.cross's very values (the same products
    and differences, each rounded once) without its ~15 us of overhead per call."""
    a0, a1, a2 = a.tolist() if isinstance(a, np.ndarray) else a
    b0, b1, b2 = b.tolist() if isinstance(b, np.ndarray) else b
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def fundamental_forms(ru, rw, ruu, ruw, rww, n) -> FundamentalForms:
    """Coefficients of I and II (II taken against ``n``)."""
    return FundamentalForms(
        float(ru @ ru), float(ru @ rw), float(rw @ rw),
        float(ruu @ n), float(ruw @ n), float(rww @ n),
    )


def tangent_coordinates(ff: FundamentalForms, ru, rw, t) -> tuple[float, float]:
    """(a, b) with a r_u + b r_w the projection of 3-D vector ``t`` on the tangent plane."""
    tu, tw = float(ru @ t), float(rw @ t)
    det = ff.E * ff.G - ff.F * ff.F
    return (ff.G * tu - ff.F * tw) / det, (ff.E * tw - ff.F * tu) / det


def normal_curvature(ff: FundamentalForms, a: float, b: float) -> float:
    """k = II(a, b) / I(a, b) for the parameter direction (a, b)."""
    num = ff.L * a * a + 2.0 * ff.M * a * b + ff.N * b * b
    den = ff.E * a * a + 2.0 * ff.F * a * b + ff.G * b * b
    return num / den


def principal_curvatures(ff: FundamentalForms, ru, rw) -> PrincipalCurvatures:
    """Principal curvatures from the mean and Gaussian curvature, with their directions."""
    det = ff.E * ff.G - ff.F * ff.F
    H = (ff.E * ff.N - 2.0 * ff.F * ff.M + ff.G * ff.L) / (2.0 * det)
    K = (ff.L * ff.N - ff.M * ff.M) / det
    disc = math.sqrt(max(H * H - K, 0.0))
    k_max, k_min = H + disc, H - disc
    directions = []
    for k in (k_max, k_min):
        # (II - k I) (a, b) = 0: take the row with the larger norm; umbilic -> r_u.
        r1 = (ff.L - k * ff.E, ff.M - k * ff.F)
        r2 = (ff.M - k * ff.F, ff.N - k * ff.G)
        row = r1 if math.hypot(*r1) >= math.hypot(*r2) else r2
        scale = math.hypot(*row)
        if scale < 1e-12 * (abs(ff.L) + abs(ff.M) + abs(ff.N) + 1e-300):  # relative 0 row
            d = np.array(ru, dtype=float)
        else:
            a, b = -row[1], row[0]
            d = a * ru + b * rw
        directions.append(d / np.linalg.norm(d))
    d_max, d_min = directions
    if abs(k_max - k_min) < 1e-12 * max(1.0, abs(k_max)):   # umbilic to round-off
        # umbilic: any orthonormal pair will do
        d_min = np.cross(np.cross(ru, rw), d_max)
        d_min /= np.linalg.norm(d_min)
    return PrincipalCurvatures(k_max, k_min, d_max, d_min)


def geodesic_torsion(pc: PrincipalCurvatures, t) -> float:
    """Geodesic torsion along unit tangent ``t``: (k_max - k_min) sin(phi) cos(phi).

    phi is the angle from the k_max direction to ``t``; the sign follows the orientation of
    (d_max, d_min); the error bounds use only its magnitude.
    """
    c = float(pc.d_max @ t)
    s = float(pc.d_min @ t)
    norm = c * c + s * s
    return (pc.k_max - pc.k_min) * s * c / norm
