"""Solve a cutter position touching both surfaces precisely (Newton), once before the loop.

Unknowns: the contact parameters (u1, w1, u2, w2). Equations: the two offset points
o_i = r_i + offset_i n_i coincide (3 equations) and the centre lies in the plane through
a seed point P0 normal to the intersection direction t0 (1 equation). Kernel-free.
"""

from __future__ import annotations

import numpy as np

from ..errors import StartPointError
from .stepper import Tangency
from ..tolerances import DEFAULT, Tolerances


def offset_point_and_jacobian(surface, offset: float, u: float, w: float):
    """o = r + offset n at (u, w) and its (3, 2) Jacobian d o / d(u, w); also n."""
    r, ru, rw, ruu, ruw, rww = (np.array(v) for v in surface.derivative_tuples(u, w))
    c = np.cross(ru, rw)
    cn = np.linalg.norm(c)
    if cn == 0.0:
        raise StartPointError(f"{surface!r}: singular point at (u={u:.6g}, w={w:.6g})")
    chat = c / cn
    sign = surface.normal_sign
    n = sign * chat
    jac = np.empty((3, 2))
    for col, (base, cd) in enumerate(((ru, np.cross(ruu, rw) + np.cross(ru, ruw)),
                                      (rw, np.cross(ruw, rw) + np.cross(ru, rww)))):
        dn = sign * (cd - chat * (chat @ cd)) / cn
        jac[:, col] = base + offset * dn
    return r + offset * n, jac, n


def solve_tangency(s1, s2, offsets: tuple[float, float], seed_uv1, seed_uv2, anchor,
                   direction=None, tol: Tolerances = DEFAULT, max_iter: int = 60,
                   what: str = "start") -> Tangency:
    """Newton on (u1, w1, u2, w2) from the seed parameters; the centre is kept in the plane
    through ``anchor`` (mm) normal to ``direction`` (default n1 x n2 at the seed).

    Converges to |o1 - o2| and the plane residual below ``tol.start`` (mm) or raises
    StartPointError naming ``what`` and the anchor.
    """
    x = np.array([*seed_uv1, *seed_uv2], dtype=float)
    anchor = np.asarray(anchor, dtype=float)

    def residual(x):
        o1, j1, n1 = offset_point_and_jacobian(s1, offsets[0], x[0], x[1])
        o2, j2, n2 = offset_point_and_jacobian(s2, offsets[1], x[2], x[3])
        return o1, o2, j1, j2, n1, n2

    o1, o2, j1, j2, n1, n2 = residual(x)
    t0 = np.cross(n1, n2) if direction is None else np.asarray(direction, dtype=float)
    if np.linalg.norm(t0) < tol.tangent_sin:
        raise StartPointError(f"{what}: the faces are tangent near {tuple(anchor.round(4))}: "
                              "no intersection direction")
    t0 = t0 / np.linalg.norm(t0)
    err = np.inf
    for _ in range(max_iter):
        F = np.concatenate([o1 - o2, [(0.5 * (o1 + o2) - anchor) @ t0]])
        err = float(np.abs(F).max())
        if err < tol.start:
            p = 0.5 * (o1 + o2)
            u1, w1 = s1.wrap(x[0], x[1])
            u2, w2 = s2.wrap(x[2], x[3])
            return Tangency(tuple(map(float, p)), (float(u1), float(w1)), (float(u2), float(w2)))
        J = np.zeros((4, 4))
        J[:3, :2], J[:3, 2:] = j1, -j2
        J[3, :2], J[3, 2:] = 0.5 * (t0 @ j1), 0.5 * (t0 @ j2)
        try:
            dx = np.linalg.lstsq(J, -F, rcond=None)[0]
        except np.linalg.LinAlgError as exc:
            raise StartPointError(f"{what}: singular tangency system near "
                                  f"{tuple(anchor.round(4))}") from exc
        # damped step: halve until the residual decreases
        lam = 1.0
        for _ in range(30):
            try:
                trial = residual(x + lam * dx)
            except StartPointError:
                lam *= 0.5
                continue
            Ft = np.concatenate([trial[0] - trial[1],
                                 [(0.5 * (trial[0] + trial[1]) - anchor) @ t0]])
            if np.abs(Ft).max() < err or lam < 1e-6:
                break
            lam *= 0.5
        x = x + lam * dx
        o1, o2, j1, j2, n1, n2 = trial
    raise StartPointError(
        f"{what}: no cutter position touching both surfaces found near "
        f"{tuple(anchor.round(4))} (residual {err:.3g} mm after {max_iter} Newton steps)")
