"""Drive the interpolator period by period: state, stop rules, and the record of cycles.

A real-time caller builds a :class:`Stepper` and calls :meth:`Stepper.step` once per
interpolation period; each call returns the axis increment dp_K (mm) for the next period,
or None once the path has stopped (``stop_reason`` says why). The feed may change between
calls (override, ramps). :func:`cadcnc.intersection_path` is a loop over this class.
Kernel-free, like :mod:`cadcnc.interp.cycle`.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..job import MIN_STEP, check_number, check_step
from .cycle import (
    BOUNDARY, CLOSED, CURVATURE, DIVERGED, END, MAX_CYCLES, SINGULAR, Contact, StopCycle,
    SurfaceLike, Track, accurate_step, advance, check_curvature, track,
)
from ..tolerances import DEFAULT, Tolerances
from ..trim import OUTSIDE
from .record import PathRecord
from .vec3 import Vec, dot, norm, scale, sub


@dataclass(frozen=True)
class Tangency:
    """A cutter position touching both surfaces: centre p (mm) and contact parameters."""

    p: Vec
    uv1: tuple[float, float]
    uv2: tuple[float, float]


class Stepper:
    """The interpolator's state machine: one :meth:`step` per interpolation period.

    ``offsets`` are each surface's offset distance (R + C for a part face, 0 for a guide
    surface). ``direction`` is the initial travel direction (only its sign against
    n1 x n2 matters). With ``end`` the last step is shortened to land on it; with
    ``closed`` the end is the start, reached after going once around.

    Each step is the commanded f = F Ts, shortened where the chord, the turn of the
    normals or the predicted point error would exceed ``tol.accuracy``
    (:func:`~cadcnc.interp.cycle.accurate_step`, closed form, once per step). Like a feed
    override, this is counted: ``accuracy_cycles`` steps were shortened, the shortest to
    ``accuracy_ratio`` of F Ts; ``record.ratio`` holds it per cycle. The commanded step
    of the job must be at least MIN_STEP (1e-6 mm); a later override may ask for less.
    """

    def __init__(self, s1: SurfaceLike, s2: SurfaceLike, offsets: tuple[float, float],
                 start: Tangency, *, feed: float, period: float, direction: Vec,
                 end: Tangency | None = None, closed: bool = False,
                 tol: Tolerances = DEFAULT, max_cycles: int = 1_000_000,
                 record: bool = True, check_boundary: bool = True):
        self.tol = tol
        self.period = check_number("period", period, "s")
        self.feed = self._check_feed(feed)
        check_step(self.feed, self.period)
        self.c1 = Contact(s1, float(offsets[0]), *start.uv1)
        self.c2 = Contact(s2, float(offsets[1]), *start.uv2)
        # spare contacts evaluated at the next cycle's parameters, swapped in on success
        self._n1, self._n2 = self.c1.copy(), self.c2.copy()
        self.p: Vec = tuple(map(float, start.p))
        d = norm(direction)
        self.t: Vec = scale(direction, 1.0 / d) if d > 0 else (0.0, 0.0, 0.0)
        self.end = Tangency(start.p, start.uv1, start.uv2) if closed else end
        self.closed = closed
        self.max_cycles = max_cycles
        self.check_boundary = check_boundary
        self.cycles = 0
        self.travelled = 0.0
        self.stop_reason: str | None = None
        self.stop_detail = ""
        self.accuracy_cycles = 0      # cycles whose step was shortened for accuracy
        self.accuracy_ratio = 1.0     # the smallest step / commanded step among them
        self._tr: Track | None = None
        self._ratio = 1.0
        self._last: tuple | None = None  # k1, k2 and contact points of the last cycle
        self.record = PathRecord() if record else None
        if self.record is not None:
            self.record.add(self.p, self.c1, self.c2, 0.0, 0.0)

    @staticmethod
    def _check_feed(feed: float) -> float:
        return check_number("feed", feed, "mm/min")

    @property
    def step_length(self) -> float:
        """f = F * Ts in mm (feed mm/min, period s)."""
        return self.feed * self.period / 60.0

    @property
    def stopped(self) -> bool:
        return self.stop_reason is not None

    def _stop(self, reason: str, detail: str) -> None:
        self.stop_reason, self.stop_detail = reason, detail

    def step(self, feed: float | None = None) -> Vec | None:
        """Compute the next period's axis increment dp_K (mm); None once stopped."""
        if self.stop_reason is not None:
            return None
        if feed is not None:
            self.feed = self._check_feed(feed)
        if self.cycles >= self.max_cycles:
            self._stop(MAX_CYCLES, f"cycle limit {self.max_cycles} reached")
            return None
        f_cmd = self.step_length
        self._ratio = 1.0
        try:  # direction and curvatures of the current state: the same for every trial
            self._tr = track(self.c1, self.c2, self.t, self.tol)
        except StopCycle as stop:
            self._tr, failure = None, (stop.reason, stop.detail)
        f = f_cmd if self._tr is None else self._accurate(f_cmd)
        landing = self._landing(f)
        if landing is not None or self.stop_reason is not None:
            return landing
        if self._tr is None:
            self._stop(failure[0], failure[1] + " (no step possible from the current point)")
            return None
        failure = self._try(f)
        if failure is None:
            return self._commit(*self._trial, f)
        return self._land_on_limit(f, failure)

    def _accurate(self, f_cmd: float) -> float:
        """The commanded step, shortened where the chord sag or the predicted error would
        exceed ``tol.accuracy`` (never below MIN_STEP); counted like a feed override."""
        tr = self._tr
        slopes = (0.0, 0.0)
        if self._last is not None:   # |k'| between the last two contacts of each surface
            k1, k2, r1, r2 = self._last
            slopes = tuple(abs(k - k_old) / d if d > 0.0 else 0.0 for k, k_old, d in (
                (tr.k1, k1, norm(sub(self.c1.r, r1))), (tr.k2, k2, norm(sub(self.c2.r, r2)))))
        f = accurate_step(self.p, self.c1, self.c2, tr, f_cmd, self.tol.accuracy, slopes)
        if f < f_cmd:
            f = max(f, min(MIN_STEP, f_cmd))
            self._ratio = f / f_cmd
        else:
            self._ratio = 1.0
        return f

    # -- pieces of a step -----------------------------------------------------------------
    def _advance(self, f: float) -> tuple[Vec, Vec]:
        """Run one cycle into the spare contacts; raises StopCycle on a geometric stop."""
        t = self._tr.t
        p_e, uv1, uv2 = advance(self.p, self.c1, self.c2, self._tr, f, self.tol)
        for spare, uv, label in ((self._n1, uv1, 1), (self._n2, uv2, 2)):
            spare.move_to(*uv)
            if spare.singularity < self.tol.near_singular:
                raise StopCycle(SINGULAR, f"surface {label}: contact reaches a singular "
                                          f"parameter point (u={spare.u:.6g}, w={spare.w:.6g})")
            eps = norm(sub(p_e, spare.centre()))
            if eps > self.tol.diverged:
                self._raise_if_at_curvature_limit(eps)
                raise StopCycle(DIVERGED, f"surface {label}: carried error {eps:.4g} mm "
                                          f"exceeds {self.tol.diverged:g} mm")
            # the new contact too: a point whose ball cannot touch there is never emitted
            check_curvature(spare, spare.curvature(t), f"surface {label}")
        return p_e, t

    def _raise_if_at_curvature_limit(self, eps: float) -> None:
        """Lost track where R' k_max nears 1: stop as the curvature limit, the true cause.
        There the offset surface folds: its contact moves 1 / (1 - R' k) times as fast as
        the centre along the principal direction, and no step keeps it."""
        for c, label in ((self.c1, 1), (self.c2, 2)):
            k = c.max_curvature()
            if c.offset * k >= 1.0 - self.tol.curvature_near:
                raise StopCycle(CURVATURE, f"surface {label}: concave curvature k = {k:.6g} "
                                           f"1/mm reaches the ball's (R' k = "
                                           f"{c.offset * k:.6g}): the contact runs away "
                                           f"(carried error {eps:.4g} mm)")

    def _try(self, f: float) -> tuple[str, str] | None:
        """Attempt a cycle of step f: None (and ``self._trial`` = (p_e, t)) on success,
        else the (reason, detail) that forbids it."""
        try:
            p_e, t = self._advance(f)
        except StopCycle as stop:
            return stop.reason, stop.detail
        if self.check_boundary:
            left = self._left_face(p_e, t)
            if left:
                return BOUNDARY, f"contact on {left} reached the boundary of its face"
        self._trial = (p_e, t)
        return None

    def _land_on_limit(self, f: float, failure: tuple[str, str]) -> Vec | None:
        """Shorten the step to the limit the geometry allows (a contact on its face's
        boundary, R' k reaching 1, a singular point, tangent faces), commit it, and stop.

        Bisection on the step length, 48 halvings (to ~f * 4e-15); the reason reported is
        the one found next to the limit. Only trials that pass every check are committed.
        """
        lo, hi = 0.0, 1.0
        for _ in range(48):
            mid = 0.5 * (lo + hi)
            found = self._try(mid * f)
            if found is None:
                lo = mid
            else:
                hi, failure = mid, found
        reason, detail = failure
        if lo * f < 1e-12 or self._try(lo * f) is not None:
            self._stop(reason, detail + " (no step possible from the current point)")
            return None
        dp = self._commit(*self._trial, lo * f)
        self._stop(reason, detail)
        return dp

    def _left_face(self, p_e: Vec, t: Vec) -> str:
        """Which spare contact lies outside its trimmed face ('' if none).

        The approximate contact q carries an O(f^2) error, so a contact running along a
        boundary (radius 0) may fall outside by its own approximation error. When q is
        outside, the contact is re-estimated by one more inverse step towards p_e (no new
        evaluation); it has left the face only if that estimate is outside as well.
        """
        names = []
        for spare, label in ((self._n1, "surface 1"), (self._n2, "surface 2")):
            surface = spare.surface
            if surface.classify(spare.u, spare.w) != OUTSIDE:
                continue
            # tangent-plane projection of the remaining offset (eq. 5's 2x2 system is
            # ill-conditioned when what remains is mostly along the normal)
            k = spare.curvature(t)
            du, dw = spare.tangent_coords(scale(sub(p_e, spare.centre()),
                                                1.0 / (1.0 - k * spare.offset)))
            if surface.classify(spare.u + du, spare.w + dw) == OUTSIDE:
                names.append(label)
        return " and ".join(names)

    def _landing(self, f: float) -> Vec | None:
        """Land exactly on the end point when it is within this step (shortened last step)."""
        end = self.end
        if end is None or self.travelled < 2.0 * f:
            return None
        d = sub(end.p, self.p)
        dist = norm(d)
        if dist <= self.tol.end_reached:  # the last full step already landed on it
            self._stop(CLOSED if self.closed else END, "end point reached")
            return None
        if dist > f or dot(d, self.t) <= 0.0:
            return None
        self._n1.move_to(*end.uv1)
        self._n2.move_to(*end.uv2)
        dp = self._commit(end.p, self.t, dist)
        self._stop(CLOSED if self.closed else END,
                   "closed intersection completed" if self.closed else "end point reached")
        return dp

    def _commit(self, p_e: Vec, t: Vec, f: float) -> Vec:
        dp = sub(p_e, self.p)
        step = norm(dp)
        if self._tr is not None:
            self._last = (self._tr.k1, self._tr.k2, self.c1.r, self.c2.r)
        self.p, self.t = p_e, t
        self.c1, self._n1 = self._n1, self.c1
        self.c2, self._n2 = self._n2, self.c2
        self.cycles += 1
        self.travelled += step
        if self._ratio < 1.0:
            self.accuracy_cycles += 1
            self.accuracy_ratio = min(self.accuracy_ratio, self._ratio)
        if self.record is not None:
            self.record.add(p_e, self.c1, self.c2, f, step, self._ratio)
        return dp

    def run(self, progress=None, every: int = 10000) -> "Stepper":
        """Step until stopped; ``progress(cycles, travelled_mm)`` every ``every`` cycles."""
        while self.step() is not None:
            if progress is not None and self.cycles % every == 0:
                progress(self.cycles, self.travelled)
        return self
