"""The paper's direct interpolator: track, correct, inverse; one fixed-cost cycle per period.

Kernel-free: a surface is anything with ``derivative_tuples(u, w)`` (r and its first and
second partials as float 3-tuples), ``normal_sign``, ``wrap(u, w)`` and ``classify(u, w)``
(:class:`cadcnc.geometry.face_surface.FaceSurface` is one). See docs/method.md section 3
(the equation numbers below) and docs/method.md. Lengths mm, curvatures 1/mm, feed
mm/min, period s.

The cycle from state (p, contacts q1, q2) with step f (mm):
  1. track    p* = p + f t,  t = n1 x n2 / |n1 x n2| (sign kept from the previous cycle)
  2. correct  p_e = p* + dp, dp from one 3x3 linear system (ball tangent to both curvature
              spheres, dp in the plane of o1, o2, p*; a flat direction uses the offset plane)
  3. inverse  (u_i, w_i) += 2x2 solve, for each surface: eq. 5, or where eq. 5 would
              amplify the contact's error (paper_inverse_ratio > 1: a cross curvature far
              from the one along t, e.g. a torus tube narrower than the ball) the same-cost
              linearisation through the whole shape operator (inverse_exact).
Before the cycle, ``accurate_step`` shortens the step in closed form where the chord, the
normals' turn or the predicted point error would exceed the accuracy (stepper.py).
No iteration inside a cycle: the work per cycle is constant.
"""

from __future__ import annotations

import math
from typing import NamedTuple, Protocol

from ..core.tolerances import DEFAULT, Tolerances
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
COLLISION = "collision"      # the ball or shank would come closer than allowed to a third
                             # face (the stepper's guard, docs/method.md)
STOP_REASONS = (END, CLOSED, BOUNDARY, TANGENT, CURVATURE, SINGULAR, DIVERGED, MAX_CYCLES,
                COLLISION)


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
        self.singularity = cn / (E + G + 1e-300)   # 0 / 0 -> 0
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

    def max_curvature(self) -> float:
        """The larger principal curvature (1/mm; > 0 concave seen from the cutter): the
        largest normal curvature over all tangent directions, the root of
        det(II - k I) = 0."""
        a = self.E * self.G - self.F * self.F
        b = self.E * self.N - 2.0 * self.F * self.M + self.G * self.L
        c = self.L * self.N - self.M * self.M
        return (b + math.sqrt(max(b * b - 4.0 * a * c, 0.0))) / (2.0 * a)

    def centre(self) -> Vec:
        """q + offset n: where this contact puts the cutter centre."""
        return axpy(self.offset, self.n, self.r)


class StopCycle(Exception):
    """Raised inside a cycle when the geometry forbids it; carries a stop reason and, for a
    rule with a continuous measure, its ``margin`` (< 0 or, for curvature, <= 0 broken;
    NaN where the rule is a yes/no answer). Landing solves for the margin's zero."""

    def __init__(self, reason: str, detail: str, margin: float = math.nan):
        super().__init__(detail)
        self.reason = reason
        self.detail = detail
        self.margin = margin


def tangent_detail(s: float, tol: Tolerances) -> str:
    return f"faces tangent: |n1 x n2| = {s:.3g} < {tol.tangent_sin:g}"


def curvature_detail(label: str, k: float, rk: float) -> str:
    return (f"{label}: concave curvature k = {k:.6g} 1/mm is tighter than the ball "
            f"(R' k = {rk:.4g} >= 1)")


def singular_detail(label: str, u: float, w: float) -> str:
    return f"{label}: contact reaches a singular parameter point (u={u:.6g}, w={w:.6g})"


def diverged_detail(label: str, eps: float, tol: Tolerances) -> str:
    return f"{label}: carried error {eps:.4g} mm exceeds {tol.diverged:g} mm"


def boundary_detail(left: str) -> str:
    return f"contact on {left} reached the boundary of its face"


CORRECTION_SINGULAR = ("correction system singular: the two spheres' normals are parallel "
                       "(tangent faces)")
MOVE_UNDEFINED = "the contact's move is undefined: a principal curvature equals 1/R'"


def track_direction(c1: Contact, c2: Contact, t_prev: Vec, tol: Tolerances) -> Vec:
    """t = n1 x n2 / |n1 x n2|, signed to agree with the previous direction (eq. 3)."""
    m = cross(c1.n, c2.n)
    s = norm(m)
    if s < tol.tangent_sin:
        raise StopCycle(TANGENT, tangent_detail(s, tol))
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
        raise StopCycle(TANGENT, CORRECTION_SINGULAR)
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


def inverse_exact(c: Contact, p_e: Vec) -> tuple[float, float]:
    """(du, dw) moving contact c under p_e through the whole shape operator: one 2x2 solve.

    The centre a contact at (u, w) puts the ball at is c(u, w) = r + R' n, with
    c_u . r_u = E - R' L, c_u . r_w = c_w . r_u = F - R' M, c_w . r_w = G - R' N
    (Weingarten). Solving (I - R' II) (du, dw) = ((p_e - c) . r_u, (p_e - c) . r_w) is the
    linearisation of c(u, w) = p_e in the tangent plane: each direction of the contact's
    move is divided by its own 1 - R' k, where eq. 5 divides every direction by that of t.
    """
    d = sub(p_e, c.centre())
    R = c.offset
    a11, a12, a22 = c.E - R * c.L, c.F - R * c.M, c.G - R * c.N
    b1, b2 = dot(d, c.ru), dot(d, c.rw)
    det = a11 * a22 - a12 * a12
    if det == 0.0:
        raise StopCycle(CURVATURE, MOVE_UNDEFINED)
    return (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det


def principal_curvatures(c: Contact) -> tuple[float, float]:
    """(k_max, k_min) at contact c, 1/mm, from the mean and Gaussian curvature."""
    det = c.E * c.G - c.F * c.F
    H = (c.E * c.N - 2.0 * c.F * c.M + c.G * c.L) / (2.0 * det)
    K = (c.L * c.N - c.M * c.M) / det
    disc = math.sqrt(max(H * H - K, 0.0))
    return H + disc, H - disc


def paper_inverse_ratio(c: Contact, k: float) -> float:
    """How much eq. 5 multiplies the contact estimate's error per cycle (contracts if < 1).

    Eq. 5 divides the centre's displacement by 1 - R' k in every direction; along a
    principal direction j the contact truly moves 1 / (1 - R' k_j) times the centre, so an
    error along j is multiplied by R' (k_j - k) / (1 - R' k). This is the largest of the two
    (the paper's eq. 15 factor g R' / (1 + |k| R') is the same for convex k).
    """
    if c.offset == 0.0:
        return 0.0
    k_max, k_min = principal_curvatures(c)
    return c.offset * max(abs(k_max - k), abs(k_min - k)) / abs(1.0 - c.offset * k)


def check_curvature(c: Contact, k: float, label: str) -> None:
    """Refuse a concave curvature the ball cannot follow without gouging (R' k >= 1)."""
    if c.offset * k >= 1.0:
        raise StopCycle(CURVATURE, curvature_detail(label, k, c.offset * k), 1.0 - c.offset * k)


class Track(NamedTuple):
    """What a cycle needs from the state before any step length is chosen.

    ``t`` the track direction, ``k1``/``k2`` the normal curvatures along it, ``exact1``/
    ``exact2`` whether that contact is moved by :func:`inverse_exact` (where eq. 5 would
    amplify its error: :func:`paper_inverse_ratio` > ``PAPER_INVERSE_LIMIT``).
    """

    t: Vec
    k1: float
    k2: float
    exact1: bool
    exact2: bool


# eq. 5 amplifies a contact's error where paper_inverse_ratio exceeds 1; the margin keeps
# rounding out of the choice (a round pocket of radius 2 R' sits at exactly 1: its vertical
# error mode is neutral and never excited, and eq. 5 keeps following it)
PAPER_INVERSE_LIMIT = 1.0 + 1e-9


def track(c1: Contact, c2: Contact, t_prev: Vec, tol: Tolerances = DEFAULT) -> Track:
    """Track direction and curvatures at the current contacts; refuses R' k >= 1."""
    t = track_direction(c1, c2, t_prev, tol)
    k1, k2 = c1.curvature(t), c2.curvature(t)
    check_curvature(c1, k1, "surface 1")
    check_curvature(c2, k2, "surface 2")
    return Track(t, k1, k2, paper_inverse_ratio(c1, k1) > PAPER_INVERSE_LIMIT,
                 paper_inverse_ratio(c2, k2) > PAPER_INVERSE_LIMIT)


def centre_curvature(c1: Contact, c2: Contact, k1: float, k2: float) -> float:
    """Curvature (1/mm) of the centre's path in the cycle's model, from the contacts alone.

    Along t, offset surface i curves by kappa_i = k_i / (1 - R'_i k_i) towards n_i (the
    curvature sphere of radius d_i of eq. 4). The path lies on both, so its curvature vector
    lies in the plane of n1, n2 with components kappa_i along n_i (Meusnier):
    |kappa|^2 = (kappa_1^2 + kappa_2^2 - 2 c kappa_1 kappa_2) / (1 - c^2), c = n1 . n2.
    """
    a = k1 / (1.0 - c1.offset * k1)
    b = k2 / (1.0 - c2.offset * k2)
    c = dot(c1.n, c2.n)
    return math.sqrt(max(a * a + b * b - 2.0 * c * a * b, 0.0) / max(1.0 - c * c, 1e-300))  # no / 0


def model_step(c: Contact, k: float, t: Vec, carried: Vec, slope: float,
               budget: float) -> float:
    """The longest step (mm) whose predicted error on this surface stays within ``budget``.

    The cycle replaces the surface by its curvature sphere along t (eq. 4). Over a step f
    the contact moves by z = f a + e, a the move for a unit centre step along t and e the
    move that absorbs the carried error ``carried`` = p - (q + R' n), both through the
    shape operator as in :func:`inverse_exact` ((I - R' II) x = (v . r_u, v . r_w)).
    Where the sphere and the surface part, the centre is off by the gap:

    - second order, the shape: h2 = |z^T (II - k I) z| / 2, which vanishes along a
      principal direction with no carried error (a surface of revolution followed along
      a parallel); it is the paper's eq. 11/12 in the direction actually taken;
    - third order, the curvature's change along the path: h3 = |k'| |z|^3 / 6, with
      ``slope`` |k'| (1/mm^2) the change of k between the last two contacts over their
      distance (0 on the first cycle).

    Each gets half the budget. Closed form: a quadratic in f for h2, a cube root for h3.
    Where the carried error alone fills a half, the step is half the one that would fill
    it without the carried error (never 0: the step cannot undo an error already made).
    """
    R = c.offset
    a11, a12, a22 = c.E - R * c.L, c.F - R * c.M, c.G - R * c.N
    det = a11 * a22 - a12 * a12
    if det == 0.0:   # a principal curvature is exactly 1/R': the model says nothing
        return math.inf
    ru, rw = c.ru, c.rw
    b1, b2 = dot(t, ru), dot(t, rw)
    a0, a1 = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
    b1, b2 = dot(carried, ru), dot(carried, rw)
    e0, e1 = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
    qL, qM, qN = c.L - k * c.E, c.M - k * c.F, c.N - k * c.G   # II - k I
    q2 = abs(qL * a0 * a0 + 2.0 * qM * a0 * a1 + qN * a1 * a1)
    q1 = abs(qL * a0 * e0 + qM * (a0 * e1 + a1 * e0) + qN * a1 * e1)
    q0 = abs(qL * e0 * e0 + 2.0 * qM * e0 * e1 + qN * e1 * e1)
    # h2 <= (q2 f^2 + 2 q1 f + q0) / 2 <= budget / 2
    room = budget - q0
    if q2 == 0.0 and q1 == 0.0:
        f2 = math.inf
    elif room > 0.0:
        f2 = room / (q1 + math.sqrt(q1 * q1 + q2 * room))
    else:   # the carried error alone fills the budget; a shorter step cannot undo it
        f2 = 0.5 * math.sqrt(budget / q2) if q2 > 0.0 else math.inf
    if slope <= 0.0:
        return f2
    # h3 <= |k'| (f |a| + |e|)^3 / 6 <= budget / 2
    la = math.sqrt(max(c.E * a0 * a0 + 2.0 * c.F * a0 * a1 + c.G * a1 * a1, 0.0))
    le = math.sqrt(max(c.E * e0 * e0 + 2.0 * c.F * e0 * e1 + c.G * e1 * e1, 0.0))
    reach = (3.0 * budget / slope) ** (1.0 / 3.0)
    f3 = (reach - le) / la if reach > 2.0 * le else 0.5 * reach / la
    return min(f2, f3)


MAX_TURN = 0.1
"""rad: the most the normals (and the centre's path) may turn in one step. The sphere of
eq. 4 and the inverse of eq. 5 model the surface about the contact; a turn of 0.1 rad
keeps the contact within a tenth of a radian of its own curvature circle, however fast it
runs (1 / (1 - R' k) times the centre near R' k = 1, where the chord alone allows more)."""


def accurate_step(p: Vec, c1: Contact, c2: Contact, tr: Track, f: float, accuracy: float,
                  slopes: tuple[float, float] = (0.0, 0.0)) -> float:
    """The commanded step f, shortened so the cycle stays within ``accuracy``: closed form.

    Half the accuracy goes to the chord: a chord of length f on a path of curvature kappa
    (:func:`centre_curvature`) leaves it by kappa f^2 / 8. An eighth goes to each
    surface's predicted point error (:func:`model_step`); the measured error reaches up to
    twice that prediction, so a point stays within a quarter, a chord within the accuracy.
    Returns f itself (the same float) when no rule shortens it.
    """
    step = f
    kappa = centre_curvature(c1, c2, tr.k1, tr.k2)
    if kappa * f * f > 4.0 * accuracy:
        step = math.sqrt(4.0 * accuracy / kappa)
    if kappa * step > MAX_TURN:
        step = MAX_TURN / kappa
    for c, k, slope in ((c1, tr.k1, slopes[0]), (c2, tr.k2, slopes[1])):
        limit = model_step(c, k, tr.t, sub(p, c.centre()), slope, accuracy / 4.0)
        if limit < step:
            step = limit
    return step


def advance(p: Vec, c1: Contact, c2: Contact, tr: Track, f: float,
            tol: Tolerances = DEFAULT) -> tuple[Vec, tuple[float, float], tuple[float, float]]:
    """Correct p + f t onto both surfaces and move the contacts: (p_e, uv1_e, uv2_e)."""
    p_e = correct(axpy(f, tr.t, p), c1, c2, tr.k1, tr.k2, tol)
    du1, dw1 = inverse_exact(c1, p_e) if tr.exact1 else inverse(c1, tr.k1, p_e)
    du2, dw2 = inverse_exact(c2, p_e) if tr.exact2 else inverse(c2, tr.k2, p_e)
    return p_e, (c1.u + du1, c1.w + dw1), (c2.u + du2, c2.w + dw2)


def cycle(p: Vec, c1: Contact, c2: Contact, t_prev: Vec, f: float,
          tol: Tolerances = DEFAULT) -> tuple[Vec, Vec, tuple[float, float], tuple[float, float]]:
    """One interpolation cycle; returns (p_e, t, (u1, w1)_e, (u2, w2)_e). Pure: no state."""
    tr = track(c1, c2, t_prev, tol)
    p_e, uv1, uv2 = advance(p, c1, c2, tr, f, tol)
    return p_e, tr.t, uv1, uv2
