"""Where a straight segment comes locally nearest a whole torus, in closed form.

A torus (centre o, unit axis z, major radius R, minor r) is at distance |g - r| from a
point, g the point's distance to the tube's core circle. Along the segment p + s d
(|d| = 1, s in [0, length]) g^2 = q - 2 R rho + R^2, q the squared distance to o and rho
the distance to the axis, both square roots of quadratics in s; g's critical points solve
(s + b)^2 rho^2(s) = R^2 (A s + B)^2 (b = (p - o).d, rho^2 = A s^2 + 2 B s + C), a
quartic. So the places where |g - r| is locally least are among: both ends, the quartic's
real roots, and the crossings of g = r between them. A face of the torus is met at its
interior only where the segment's point has its (unique) foot inside the face, i.e. at one
of these places, or at a point on the axis (every point of a circle is then a foot).

Used by the guard (:mod:`cadcnc.guard.analytic_faces`, vertical segments) and by the gate
(:mod:`cadcnc.verification.probe`, any move), each measuring the face itself. Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..interp.vec3 import axpy, dot, sub

EPS = 1e-12   # relative: below this a direction or radius is degenerate
UP = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Torus:
    """A torus: centre ``o``, unit axis ``z`` (3-tuples), radii ``major`` > ``minor``."""

    o: tuple[float, float, float]
    z: tuple[float, float, float]
    major: float
    minor: float


def core_distances(t: Torus, p, length: float, d=UP) -> tuple[list, list, Callable] | None:
    """(candidates s, g at each, g): both ends and the real parts of the quartic's roots
    in [0, length] (polished by Newton where that lowers the quartic), g(s) the distance
    from p + s d to the core circle (mm); None where the segment meets the axis (there g
    has a kink and the quartic degenerates)."""
    qa, qb, qc = _radial(t, p, d)
    s_v = axis_nearest(t, p, length, d)
    if qa * s_v * s_v + 2.0 * qb * s_v + qc < (EPS * t.major) ** 2 + 1e-18:  # mm^2
        return None                                      # the segment meets the axis
    b = dot(sub(p, t.o), d)                            # q' / 2 = s + b
    quartic = np.convolve([1.0, 2.0 * b, b * b], [qa, 2.0 * qb, qc])   # 5 coefficients
    quartic[2:] -= t.major ** 2 * np.array([qa * qa, 2.0 * qa * qb, qb * qb])
    cands = [0.0, length]
    coef = quartic.tolist()
    deriv = np.polyder(quartic).tolist()
    # every root's real part is a candidate: g's value at an extra point stays within
    # g's true range, and a near-double real root may come out slightly complex
    for root in _roots(quartic):
        s = float(root.real)
        for _ in range(2):   # polish on the quartic, only where it improves
            dq = _horner(deriv, s)
            t1 = s - _horner(coef, s) / dq if dq else s
            if not abs(_horner(coef, t1)) < abs(_horner(coef, s)):
                break
            s = t1
        if 0.0 <= s <= length:
            cands.append(s)

    g = _core_distance(t, p, d, qa, qb, qc)
    return cands, [g(s) for s in cands], g


def _core_distance(t: Torus, p, d, qa: float, qb: float, qc: float) -> Callable:
    """g(s): the distance (mm) from p + s d to the core circle, rho^2 = qa s^2 + 2 qb s +
    qc."""
    def g(s: float) -> float:
        rho = math.sqrt(max(qa * s * s + 2.0 * qb * s + qc, 0.0))
        ax = dot(sub(axpy(s, d, p), t.o), t.z)
        return math.hypot(rho - t.major, ax)

    return g


def _radial(t: Torus, p, d) -> tuple[float, float, float]:
    """(qa, qb, qc): the squared distance from p + s d to the axis, qa s^2 + 2 qb s + qc."""
    w0 = sub(p, t.o)
    w0 = axpy(-dot(w0, t.z), t.z, w0)                 # radial part at s = 0
    e = axpy(-dot(d, t.z), t.z, d)                     # radial part of d
    return dot(e, e), dot(w0, e), dot(w0, w0)


def axis_nearest(t: Torus, p, length: float, d=UP) -> float:
    """The s in [0, length] where p + s d comes nearest the torus's axis."""
    qa, qb, _ = _radial(t, p, d)
    return min(max(-qb / qa, 0.0), length) if qa > EPS else 0.0


def crossings(t: Torus, cands: list, gs: list, g, first: bool = False) -> list[float]:
    """The s where g - r changes sign between two consecutive candidates, each found to a
    nanometre by bisection (only the first when ``first``)."""
    order = sorted(range(len(cands)), key=lambda i: cands[i])
    out = []
    for i, j in zip(order, order[1:]):
        a, b = cands[i], cands[j]
        fa = gs[i] - t.minor
        if fa == 0.0:
            out.append(a)
        elif fa * (gs[j] - t.minor) < 0.0:
            for _ in range(60):
                m = 0.5 * (a + b)
                if b - a <= 1e-9:   # mm: the crossing found to a nanometre
                    break
                if (g(m) - t.minor) * fa > 0.0:
                    a = m
                else:
                    b = m
            out.append(0.5 * (a + b))
        if first and out:
            break
    return out


def local_nearest(t: Torus, p, length: float, d=UP) -> list[float]:
    """Every s in [0, length] where p + s d may come locally nearest a face of the torus
    at the face's interior: the ends, the quartic's roots, the crossings and the point
    nearest the axis (where the segment meets it, the quartic's roots are replaced by
    those of its factored form, s = -b +- R sqrt(A))."""
    s_v = axis_nearest(t, p, length, d)
    got = core_distances(t, p, length, d)
    if got is None:   # through the axis: rho = sqrt(A) |s - s_v|, the quartic factored
        qa, qb, qc = _radial(t, p, d)
        b, root = dot(sub(p, t.o), d), t.major * math.sqrt(qa)
        cands = [0.0, length, s_v] + [s for s in (-b - root, -b + root) if 0.0 <= s <= length]
        g = _core_distance(t, p, d, qa, qb, qc)
        got = cands, [g(s) for s in cands], g
    cands, gs, g = got
    return cands + crossings(t, cands, gs, g) + [s_v]


_SUB = np.eye(4, k=-1)   # the companion matrix's ones below its diagonal


def _roots(quartic: np.ndarray) -> np.ndarray:
    """np.roots(quartic), made as np.roots makes it (the companion matrix's eigenvalues)
    without its checks where the first and last coefficients are not 0."""
    if quartic[0] == 0.0 or quartic[-1] == 0.0:
        return np.roots(quartic) if np.any(quartic) else np.empty(0)
    a = _SUB.copy()
    a[0, :] = -quartic[1:] / quartic[0]
    return np.linalg.eigvals(a)


def _horner(c: list[float], x: float) -> float:
    """The polynomial with coefficients ``c`` (highest first) at ``x``: numpy's polyval's
    operations in its order, on plain floats."""
    y = 0.0
    for v in c:
        y = y * x + v
    return y
