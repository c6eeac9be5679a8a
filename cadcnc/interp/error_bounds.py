"""The paper's error theory (docs/method.md section 4), evaluated per cycle, vectorised.

Inputs are per-point arrays from the interpolator's record; outputs are bounds in mm.
R in the paper's formulas is each surface's offset distance (R + C, or 0 for a guide
surface): the paper derives them for finishing (C = 0), where the two agree.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .cycle import PAPER_INVERSE_LIMIT


@dataclass
class SurfaceBounds:
    """Per-point bounds for one surface, each an (N,) float array (mm unless noted).

    eq11: one step with no initial error; eq12: one step with the initial error eps;
    eq15: error carried to the next cycle; eps_ss: steady-state carried error;
    eq16: steady-state machining error (inf where the steady state does not exist);
    eps: measured initial error |p - (q + R' n)|; k, k_max, k_min (1/mm), tau (1/mm).
    """

    eps: np.ndarray
    k: np.ndarray
    k_max: np.ndarray
    k_min: np.ndarray
    tau: np.ndarray
    eq11: np.ndarray
    eq12: np.ndarray
    eq15: np.ndarray
    eps_ss: np.ndarray
    eq16: np.ndarray


def _rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot products over the last axis (broadcast): (..., 3) x (..., 3) -> (...)."""
    return np.einsum("...j,...j->...", a, b)


def surface_curvatures(ru, rw, n, ff, t):
    """k along t, principal k_max/k_min and geodesic torsion tau along t, per row.

    ``ru``, ``rw``, ``n``, ``t`` (..., 3) and ``ff`` (..., 6): E, F, G, L, M, N (leading
    axes broadcast: (N, 3) for one surface, (2, N, 3) for both with t (N, 3)). Vectorised
    forms of cadcnc.geometry.differential (tests/interp/test_curvature_copies.py ties them
    together).
    """
    E, F, G, L, M, N = np.moveaxis(ff, -1, 0)
    det = E * G - F * F
    tu, tw = _rows(ru, t), _rows(rw, t)
    a = (G * tu - F * tw) / det
    b = (E * tw - F * tu) / det
    first = E * a * a + 2 * F * a * b + G * b * b
    k = (L * a * a + 2 * M * a * b + N * b * b) / first
    H = (E * N - 2 * F * M + G * L) / (2 * det)
    K = (L * N - M * M) / det
    disc = np.sqrt(np.maximum(H * H - K, 0.0))
    tau = ((E * M - F * L) * a * a + (E * N - G * L) * a * b + (F * N - G * M) * b * b) / (
        np.sqrt(det) * first)
    return k, H + disc, H - disc, tau


def bounds_for_surface(R: float, f: np.ndarray, eps: np.ndarray, k, k_max, k_min, tau,
                       mp: np.ndarray) -> SurfaceBounds:
    """Evaluate eq. 11, 12, 15, the steady state and eq. 16 for one surface."""
    ak = np.abs(k)
    dk = np.abs(k_max - k_min)
    one = 1.0 + ak * R
    coeff = dk + dk * dk * R + tau * tau * R
    with np.errstate(divide="ignore", invalid="ignore"):
        eq11 = tau * tau * R * f * f / (2 * one ** 2) + np.abs(tau) * f ** 3 / (2 * one ** 2 * mp)
        eq12 = coeff / (2 * one ** 2) * (f + eps) ** 2
        g = np.sqrt(dk * dk + tau * tau)
        eq15 = g * R * (f + eps) / one
        ss_den = 1.0 + R * (ak - g)
        eps_ss = np.where(ss_den > 0, R * g * f / ss_den, np.inf)
        eq16 = np.where(ss_den > 0, coeff / (2 * one * ss_den) * f * f, np.inf)
    eq11 = np.nan_to_num(eq11, nan=0.0)
    return SurfaceBounds(eps, k, k_max, k_min, tau, eq11, eq12, eq15, eps_ss, eq16)


def mp_length(R, k1, k2, q1, q2, n1, n2) -> np.ndarray:
    """|mp| = (rho1 + R)(rho2 + R) sqrt(1 - (n1.n2)^2) / |o1 o2| (inf where a k ~ 0).

    k1, k2 (N,); q1, q2, n1, n2 (N, 3); R a float, or (m, 1) for m offsets at once
    (then (m, N))."""
    with np.errstate(divide="ignore", invalid="ignore"):
        o1 = q1 + n1 / k1[:, None]
        o2 = q2 + n2 / k2[:, None]
        rho1, rho2 = 1 / np.abs(k1), 1 / np.abs(k2)
        s = np.sqrt(np.maximum(1 - _rows(n1, n2) ** 2, 0.0))
        mp = (rho1 + R) * (rho2 + R) * s / np.linalg.norm(o1 - o2, axis=1)
    return np.where(np.isfinite(mp), mp, np.inf)


def pair_bounds(R, points, contacts, normals, ru, rw, forms, t, f
                ) -> tuple[SurfaceBounds, SurfaceBounds]:
    """Both surfaces' bounds at once (one numpy pass for the pair, not one per surface).

    ``R`` (2,) offsets (mm); ``points`` (N, 3); ``contacts``, ``normals``, ``ru``, ``rw``
    (N, 2, 3); ``forms`` (N, 2, 6); ``t`` (N, 3) unit tangents; ``f`` (N,) steps (mm).
    Where the exact inverse moved a contact (eq. 5 would amplify its error), the paper's
    steady state of eq. 5 does not apply: eps_ss is the measured carried error and eq16
    eq. 12 from it (the step's own bound, whatever the inverse).
    """
    R = np.asarray(R, dtype=float)[:, None]                      # (2, 1)
    pair = [np.swapaxes(a, 0, 1) for a in (contacts, normals, ru, rw, forms)]
    q, n = pair[0], pair[1]                                      # (2, N, 3)
    k, kmax, kmin, tau = surface_curvatures(pair[2], pair[3], n, pair[4], t)
    eps = np.linalg.norm(points - (q + R[:, :, None] * n), axis=2)
    mp = mp_length(R, k[0], k[1], q[0], q[1], n[0], n[1])
    b = bounds_for_surface(R, f, eps, k, kmax, kmin, tau, mp)
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = R * np.maximum(np.abs(kmax - k), np.abs(kmin - k)) / np.abs(1.0 - R * k)
    exact = rho > PAPER_INVERSE_LIMIT
    if exact.any():
        b.eps_ss = np.where(exact, eps, b.eps_ss)
        b.eq16 = np.where(exact, b.eq12, b.eq16)
    names = [f.name for f in fields(SurfaceBounds)]
    return tuple(SurfaceBounds(**{m: getattr(b, m)[i] for m in names}) for i in (0, 1))
