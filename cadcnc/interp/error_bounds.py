"""The paper's error theory (docs/method.md section 4), evaluated per cycle, vectorised.

Inputs are per-point arrays from the interpolator's record; outputs are bounds in mm.
R in the paper's formulas is each surface's offset distance (R + C, or 0 for a guide
surface): the paper derives them for finishing (C = 0), where the two agree.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
    return np.einsum("ij,ij->i", a, b)


def surface_curvatures(ru, rw, n, ff, t):
    """k along t, principal k_max/k_min and geodesic torsion tau along t, per row.

    ``ff`` is (N, 6): E, F, G, L, M, N. Vectorised forms of cadcnc.geometry.differential (tests/test_curvature_copies.py
    ties them together).
    """
    E, F, G, L, M, N = ff.T
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


def mp_length(R: float, k1, k2, q1, q2, n1, n2) -> np.ndarray:
    """|mp| = (rho1 + R)(rho2 + R) sqrt(1 - (n1.n2)^2) / |o1 o2| (inf where a k ~ 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        o1 = q1 + n1 / k1[:, None]
        o2 = q2 + n2 / k2[:, None]
        rho1, rho2 = 1 / np.abs(k1), 1 / np.abs(k2)
        s = np.sqrt(np.maximum(1 - _rows(n1, n2) ** 2, 0.0))
        mp = (rho1 + R) * (rho2 + R) * s / np.linalg.norm(o1 - o2, axis=1)
    return np.where(np.isfinite(mp), mp, np.inf)
