"""The paper's direct interpolator: track, correct, inverse; one fixed-cost cycle per period.

Kernel-free: a surface is anything with ``derivative_tuples(u, w)`` (r and its first and
second partials as float 3-tuples), ``normal_sign``, ``wrap(u, w)`` and ``classify(u, w)``
(:class:`cadcnc.geometry.face_surface.FaceSurface` is one). See docs/method.md section 3
(the equation numbers below) and docs/interpolator.md. Lengths mm, curvatures 1/mm, feed
mm/min, period s.

The cycle from state (p, contacts q1, q2) with step f (mm):
  1. track    p* = p + f t,  t = n1 x n2 / |n1 x n2| (sign kept from the previous cycle)
  2. correct  p_e = p* + dp, dp from one 3x3 linear system (ball tangent to both curvature
              spheres, dp in the plane of o1, o2, p*; a flat direction uses the offset plane)
  3. inverse  (u_i, w_i) += 2x2 solve, for each surface.
No iteration inside a cycle: the work per cycle is constant.
"""

from __future__ import annotations

import math
from typing import Protocol

from ..tolerances import DEFAULT, Tolerances
from .vec3 import Vec, add, axpy, cross, dot, norm, scale, solve3, sub

# stop reasons (Toolpath.stop_reason)
END = "end"                  # reached the requested end point
CLOSED = "closed"            # a closed intersection has been completed
BOUNDARY = "boundary"        # a contact point reached the boundary of its trimmed face
TANGENT = "tangent"          # the faces are tangent: n1 x n2 vanishes
CURVATURE = "curvature"      # concave curvature tighter than the ball: R' k >= 1
SINGULAR = "singular"        # a singular parameter point (pole, apex, collapsed edge)
DIVERGED = "diverged"        # the carried error exceeded its safety limit
MAX_CYCLES = "max_cycles"    # the cycle limit was reached
STOP_REASONS = (END, CLOSED, BOUNDARY, TANGENT, CURVATURE, SINGULAR, DIVERGED, MAX_CYCLES)


class SurfaceLike(Protocol):
    normal_sign: float

    def derivative_tuples(self, u: float, w: float) -> tuple: ...

    def wrap(self, u: float, w: float) -> tuple[float, float]: ...

    def classify(self, u: float, w: float) -> str: ...


class Contact:
    """The approximate contact point q on one surface, with its local geometry.

    ``offset`` is the distance from the surface to the cutter centre along n: R + C for a
    part face, 0 for a guide surface that carries the centre itself.
    """

    __slots__ = ("surface", "offset", "u", "w", "r", "ru", "rw", "n",
                 "E", "F", "G", "L", "M", "N", "singularity")

    def __init__(self, surface: SurfaceLike, offset: float, u: float, w: float):
        self.surface = surface
        self.offset = offset
        self.move_to(u, w)

    def move_to(self, u: float, w: float) -> None:
        """Evaluate the surface at (u, w) (wrapped) and refresh the local geometry."""
        u, w = self.surface.wrap(u, w)
        r, ru, rw, ruu, ruw, rww = self.surface.derivative_tuples(u, w)
        c = cross(ru, rw)
        cn = norm(c)
        E, F, G = dot(ru, ru), dot(ru, rw), dot(rw, rw)
        # the singularity ratio |r_u x r_w| / (|r_u|^2 + |r_w|^2): 0 at a singular point
        self.singularity = cn / (E + G + 1e-300)
        n = scale(c, self.surface.normal_sign / cn) if cn > 0.0 else (0.0, 0.0, 0.0)
        self.u, self.w, self.r, self.ru, self.rw, self.n = u, w, r, ru, rw, n
        self.E, self.F, self.G = E, F, G
        self.L, self.M, self.N = dot(ruu, n), dot(ruw, n), dot(rww, n)

    def copy(self) -> "Contact":
        other = object.__new__(Contact)
        for name in Contact.__slots__:
            setattr(other, name, getattr(self, name))
        return other

    def tangent_coords(self, t: Vec) -> tuple[float, float]:
        """(a, b) with a r_u + b r_w the tangent-plane projection of t."""
        tu, tw = dot(self.ru, t), dot(self.rw, t)
        det = self.E * self.G - self.F * self.F
        return (self.G * tu - self.F * tw) / det, (self.E * tw - self.F * tu) / det

    def curvature(self, t: Vec) -> float:
        """Normal curvature (1/mm) along tangent t; > 0 concave seen from the cutter."""
        a, b = self.tangent_coords(t)
        return ((self.L * a * a + 2.0 * self.M * a * b + self.N * b * b)
                / (self.E * a * a + 2.0 * self.F * a * b + self.G * b * b))

    def centre(self) -> Vec:
        """q + offset n: where this contact puts the cutter centre."""
        return axpy(self.offset, self.n, self.r)


class StopCycle(Exception):
    """Raised inside a cycle when the geometry forbids it; carries a stop reason."""

    def __init__(self, reason: str, detail: str):
        super().__init__(detail)
        self.reason = reason
        self.detail = detail


def track_direction(c1: Contact, c2: Contact, t_prev: Vec, tol: Tolerances) -> Vec:
    """t = n1 x n2 / |n1 x n2|, signed to agree with the previous direction (eq. 3)."""
    m = cross(c1.n, c2.n)
    s = norm(m)
    if s < tol.tangent_sin:
        raise StopCycle(TANGENT, f"faces tangent: |n1 x n2| = {s:.3g} < {tol.tangent_sin:g}")
    if dot(m, t_prev) < 0.0:
        s = -s
    return scale(m, 1.0 / s)


def _sphere_row(c: Contact, k: float, p_star: Vec, tol: Tolerances) -> tuple[Vec, float]:
    """One row of the correction system (eq. 4) for contact c with normal curvature k."""
    if abs(k) < tol.flat_curvature:
        # the curvature sphere degenerates to the offset tangent plane
        return c.n, dot(sub(c.centre(), p_star), c.n)
    o = axpy(1.0 / k, c.n, c.r)             # centre of curvature
    v = sub(p_star, o)
    dist = norm(v)
    d = (1.0 - c.offset * k) / abs(k)       # ball centre's distance from o when tangent
    return scale(v, 1.0 / dist), d - dist


def correct(p_star: Vec, c1: Contact, c2: Contact, k1: float, k2: float,
            tol: Tolerances) -> Vec:
    """p_e = p* + dp with dp from the 3x3 system of eq. 4."""
    e1, b1 = _sphere_row(c1, k1, p_star, tol)
    e2, b2 = _sphere_row(c2, k2, p_star, tol)
    dp = solve3(e1, e2, cross(e1, e2), (b1, b2, 0.0))
    if dp is None:
        raise StopCycle(TANGENT, "correction system singular: the two spheres' normals are "
                                 "parallel (tangent faces)")
    return add(p_star, dp)


def inverse(c: Contact, k: float, p_e: Vec) -> tuple[float, float]:
    """(du, dw) moving contact c under the new centre p_e (eq. 5): one 2x2 solve."""
    dr = scale(sub(p_e, c.centre()), 1.0 / (1.0 - k * c.offset))
    drr = dot(dr, dr)
    if drr == 0.0:
        return 0.0, 0.0
    m = cross(c.n, dr)
    a11, a12 = dot(c.ru, m), dot(c.rw, m)
    a21, a22 = dot(c.ru, dr), dot(c.rw, dr)
    det = a11 * a22 - a12 * a21
    return (-a12 * drr) / det, (a11 * drr) / det


def check_curvature(c: Contact, k: float, label: str) -> None:
    """Refuse a concave curvature the ball cannot follow without gouging (R' k >= 1)."""
    if c.offset * k >= 1.0:
        raise StopCycle(CURVATURE, f"{label}: concave curvature k = {k:.6g} 1/mm is tighter "
                                   f"than the ball (R' k = {c.offset * k:.4g} >= 1)")


def cycle(p: Vec, c1: Contact, c2: Contact, t_prev: Vec, f: float,
          tol: Tolerances = DEFAULT) -> tuple[Vec, Vec, tuple[float, float], tuple[float, float]]:
    """One interpolation cycle; returns (p_e, t, (u1, w1)_e, (u2, w2)_e). Pure: no state."""
    t = track_direction(c1, c2, t_prev, tol)
    k1, k2 = c1.curvature(t), c2.curvature(t)
    check_curvature(c1, k1, "surface 1")
    check_curvature(c2, k2, "surface 2")
    p_e = correct(axpy(f, t, p), c1, c2, k1, k2, tol)
    du1, dw1 = inverse(c1, k1, p_e)
    du2, dw2 = inverse(c2, k2, p_e)
    return p_e, t, (c1.u + du1, c1.w + dw1), (c2.u + du2, c2.w + dw2)
