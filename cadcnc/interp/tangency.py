"""Solve a cutter position touching both surfaces precisely (Newton), once before the loop.

Unknowns: the contact parameters (u1, w1, u2, w2). Equations: the two offset points
o_i = r_i + offset_i n_i coincide (3 equations) and the centre lies in the plane through
a seed point P0 normal to the intersection direction t0 (1 equation). Kernel-free.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.errors import StartPointError
from ..core.tolerances import DEFAULT, Tolerances
from .stepper import Tangency
from .vec3 import add, axpy, cross, dot, norm, scale, sub


def offset_point_and_jacobian(surface, offset: float, u: float, w: float):
    """o = r + offset n at (u, w) and its Jacobian d o / d(u, w) as two columns (do/du,
    do/dw); also n. All float 3-tuples (mm; vec3: no numpy on this path)."""
    r, ru, rw, ruu, ruw, rww = surface.derivative_tuples(u, w)
    c = cross(ru, rw)
    cn = norm(c)
    if cn == 0.0:
        raise StartPointError(f"{surface!r}: singular point at (u={u:.6g}, w={w:.6g})")
    chat = scale(c, 1.0 / cn)
    sign = surface.normal_sign
    n = scale(chat, sign)
    cols = []
    for base, cd in ((ru, add(cross(ruu, rw), cross(ru, ruw))),
                     (rw, add(cross(ruw, rw), cross(ru, rww)))):
        dn = scale(axpy(-dot(chat, cd), chat, cd), sign / cn)
        cols.append(axpy(offset, dn, base))
    return axpy(offset, n, r), tuple(cols), n


STALLS, PROGRESS = 3, 1e-3
"""Newton steps in a row that brought the residual no lower than PROGRESS of the least so
far: the search hovers at a least residual that is not 0 (no position touches both faces
near the seed; its damped steps halve to their floor), and the steps left would too.
A search that converges lowers it by 7 % or more a step (about 11 000 solves on
bug27453's corners, 2 to 6 steps each)."""


def _solve4(a: list[list[float]], b: list[float]) -> list[float]:
    """x with a x = b (4 x 4, Gaussian elimination with partial pivoting); the least-squares
    solution (numpy) where a is (nearly) singular."""
    m = [row[:] + [v] for row, v in zip(a, b)]
    size = max(abs(x) for row in a for x in row)
    for k in range(4):
        piv = max(range(k, 4), key=lambda i: abs(m[i][k]))
        if abs(m[piv][k]) <= 1e-13 * size:   # relative: a zero pivot to round-off
            return np.linalg.lstsq(np.array(a), np.array(b), rcond=None)[0].tolist()
        m[k], m[piv] = m[piv], m[k]
        for i in range(k + 1, 4):
            f = m[i][k] / m[k][k]
            if f:
                m[i] = [x - f * y for x, y in zip(m[i], m[k])]
    x = [0.0] * 4
    for k in range(3, -1, -1):
        x[k] = (m[k][4] - sum(m[k][j] * x[j] for j in range(k + 1, 4))) / m[k][k]
    return x


def solve_tangency(s1, s2, offsets: tuple[float, float], seed_uv1, seed_uv2, anchor,
                   direction=None, tol: Tolerances = DEFAULT, max_iter: int = 60,
                   what: str = "start") -> Tangency:
    """Newton on (u1, w1, u2, w2) from the seed parameters; the centre is kept in the plane
    through ``anchor`` (mm) normal to ``direction`` (default n1 x n2 at the seed).

    Converges to |o1 - o2| and the plane residual below ``tol.start`` (mm) or raises
    StartPointError naming ``what`` and the anchor (after ``max_iter`` steps, or STALLS
    steps in a row that lowered the least residual by less than PROGRESS of it).
    """
    x = [float(v) for v in (*seed_uv1, *seed_uv2)]
    anchor = tuple(float(v) for v in anchor)
    label = "(" + ", ".join(f"{v:.4f}" for v in anchor) + ")"

    def residual(x):
        o1, j1, n1 = offset_point_and_jacobian(s1, offsets[0], x[0], x[1])
        o2, j2, n2 = offset_point_and_jacobian(s2, offsets[1], x[2], x[3])
        return o1, o2, j1, j2, n1, n2

    def equations(o1, o2) -> list[float]:
        mid = scale(add(o1, o2), 0.5)
        return [*sub(o1, o2), dot(sub(mid, anchor), t0)]

    o1, o2, j1, j2, n1, n2 = residual(x)
    t0 = cross(n1, n2) if direction is None else tuple(float(v) for v in direction)
    if norm(t0) < tol.tangent_sin:
        raise StartPointError(f"{what}: the faces are tangent near {label}: "
                              "no intersection direction")
    t0 = scale(t0, 1.0 / norm(t0))
    err, best, stalled, steps = math.inf, math.inf, 0, 0
    for steps in range(1, max_iter + 1):
        F = equations(o1, o2)
        err = max(abs(v) for v in F)
        if err < tol.start:
            p = scale(add(o1, o2), 0.5)
            u1, w1 = s1.wrap(x[0], x[1])
            u2, w2 = s2.wrap(x[2], x[3])
            return Tangency(p, (float(u1), float(w1)), (float(u2), float(w2)))
        if err < best * (1.0 - PROGRESS):
            best, stalled = err, 0
        else:
            stalled += 1
            if stalled >= STALLS:
                break
        J = [[j1[0][i], j1[1][i], -j2[0][i], -j2[1][i]] for i in range(3)]
        J.append([0.5 * dot(t0, j1[0]), 0.5 * dot(t0, j1[1]),
                  0.5 * dot(t0, j2[0]), 0.5 * dot(t0, j2[1])])
        try:
            dx = _solve4(J, [-v for v in F])
        except np.linalg.LinAlgError as exc:
            raise StartPointError(f"{what}: singular tangency system near {label}") from exc
        # damped step: halve until the residual decreases
        lam = 1.0
        for _ in range(30):
            xt = [a + lam * d for a, d in zip(x, dx)]
            try:
                trial = residual(xt)
            except StartPointError:
                lam *= 0.5
                continue
            if (max(abs(v) for v in equations(trial[0], trial[1])) < err
                    or lam < 1e-6):   # damping floor: the step halved 20 times
                break
            lam *= 0.5
        x = [a + lam * d for a, d in zip(x, dx)]
        o1, o2, j1, j2, n1, n2 = trial
    raise StartPointError(
        f"{what}: no cutter position touching both surfaces found near "
        f"{label} (least residual {min(best, err):.3g} mm in {steps} Newton steps)")
