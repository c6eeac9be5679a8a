"""Drive the interpolator period by period: state, stop rules, and the record of cycles.

A real-time caller builds a :class:`Stepper` and calls :meth:`Stepper.step` once per
interpolation period; each call returns the axis increment dp_K (mm) for the next period,
or None once the path has stopped (``stop_reason`` says why). The feed may change between
calls (override, ramps). :func:`cadcnc.intersection_path` is a loop over this class.
Kernel-free, like :mod:`cadcnc.interp.cycle`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

from ..core.job import MIN_STEP, check_number, check_step
from ..core.progress import travelled_text
from ..core.tolerances import DEFAULT, Tolerances
from ..core.trim_labels import OUTSIDE
from .cycle import (
    BOUNDARY,
    CLOSED,
    COLLISION,
    CURVATURE,
    DIVERGED,
    END,
    MAX_CYCLES,
    SINGULAR,
    Contact,
    StopCycle,
    SurfaceLike,
    Track,
    accurate_step,
    advance,
    boundary_detail,
    check_curvature,
    diverged_detail,
    singular_detail,
    track,
)
from .landing import LANDING_TOL, MAX_TRIALS, land
from .record import PathRecord
from .vec3 import Vec, dot, norm, scale, sub


@dataclass(frozen=True)
class Tangency:
    """A cutter position touching both surfaces: centre p (mm) and contact parameters."""

    p: Vec
    uv1: tuple[float, float]
    uv2: tuple[float, float]


class Guard(Protocol):
    """Clearance from the faces other than the two followed (docs/method.md).

    ``margin(p)``: the signed clearance (mm) of the cutter centre p (3-tuple) from those
    faces, >= 0 clear, < 0 when the ball or shank comes closer than allowed, and a detail
    naming what is touched (e.g. "ball touches face 7"). Continuous in p: the stepper lands
    on its zero.
    """

    def margin(self, p: Vec) -> tuple[float, str]: ...


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

    ``guard`` (a :class:`Guard`, optional) is asked for every trial that passes the other
    rules; a negative margin stops the path with ``collision``, landed tangent to the
    third face like any other limit. This is the plain-Python reference;
    :func:`cadcnc.interp.compiled.new_stepper` builds the compiled one where it applies.
    """

    def __init__(self, s1: SurfaceLike, s2: SurfaceLike, offsets: tuple[float, float],
                 start: Tangency, *, feed: float, period: float, direction: Vec,
                 end: Tangency | None = None, closed: bool = False,
                 tol: Tolerances = DEFAULT, max_cycles: int = 1_000_000,
                 record: bool = True, check_boundary: bool = True, guard: Guard | None = None):
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
        self.guard = guard
        self._watch: str | None = None   # the rule whose margin a trial reports (landing)
        self._margin = math.nan          # that margin at the last trial
        self.landing_trials = 0          # trial cycles of the last landing (failed step incl.)
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

    def _may_step(self, feed: float | None) -> bool:
        """Take a feed override and apply the cycle limit: False when no step follows."""
        if self.stop_reason is not None:
            return False
        if feed is not None:
            self.feed = self._check_feed(feed)
        if self.cycles >= self.max_cycles:
            self._stop(MAX_CYCLES, f"cycle limit {self.max_cycles} reached")
            return False
        return True

    def step(self, feed: float | None = None) -> Vec | None:
        """Compute the next period's axis increment dp_K (mm); None once stopped."""
        if not self._may_step(feed):
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
        """Run one cycle into the spare contacts; raises StopCycle on a geometric stop.

        Every rule with a continuous margin keeps the smallest one of the watched rule
        (``self._watch``) in ``self._margin``; a StopCycle carries its own rule's margin."""
        t = self._tr.t
        tol, watch = self.tol, self._watch
        p_e, uv1, uv2 = advance(self.p, self.c1, self.c2, self._tr, f, tol)
        for spare, uv, label in ((self._n1, uv1, 1), (self._n2, uv2, 2)):
            spare.move_to(*uv)
            m = spare.singularity - tol.near_singular
            if m < 0.0:
                raise StopCycle(SINGULAR, singular_detail(f"surface {label}", spare.u, spare.w),
                                m)
            if watch == SINGULAR:
                self._margin = min(self._margin, m)
            eps = norm(sub(p_e, spare.centre()))
            if eps > tol.diverged:
                limit = self._curvature_limit(eps)
                if limit is not None:
                    raise StopCycle(*limit)
                raise StopCycle(DIVERGED, diverged_detail(f"surface {label}", eps, tol),
                                tol.diverged - eps)
            if watch == DIVERGED:
                self._margin = min(self._margin, tol.diverged - eps)
            # the new contact too: a point whose ball cannot touch there is never emitted
            k = spare.curvature(t)
            check_curvature(spare, k, f"surface {label}")
            if watch == CURVATURE:
                self._margin = min(self._margin, 1.0 - spare.offset * k)
        return p_e, t

    def _curvature_limit(self, eps: float) -> tuple[str, str] | None:
        """Lost track where R' k_max nears 1: (CURVATURE, detail), the true cause, or None.
        There the offset surface folds: its contact moves 1 / (1 - R' k) times as fast as
        the centre along the principal direction, and no step keeps it."""
        for c, label in ((self.c1, 1), (self.c2, 2)):
            k = c.max_curvature()
            if c.offset * k >= 1.0 - self.tol.curvature_near:
                return CURVATURE, (f"surface {label}: concave curvature k = {k:.6g} 1/mm "
                                   f"reaches the ball's (R' k = {c.offset * k:.6g}): the "
                                   f"contact runs away (carried error {eps:.4g} mm)")
        return None

    def _try(self, f: float) -> tuple[str, str] | None:
        """Attempt a cycle of step f: None (and ``self._trial`` = (p_e, t)) on success,
        else the (reason, detail) that forbids it. ``self._margin``: the margin of the
        failing rule, or on success of the watched one (NaN for yes/no rules)."""
        self._margin = math.inf
        try:
            p_e, t = self._advance(f)
        except StopCycle as stop:
            self._margin = stop.margin
            return stop.reason, stop.detail
        if self._watch not in (SINGULAR, DIVERGED, CURVATURE):
            self._margin = math.nan
        if self.check_boundary:
            left = self._left_face(p_e, t)
            if left:
                return BOUNDARY, boundary_detail(left)
        if self.guard is not None:
            clearance, detail = self.guard.margin(p_e)
            if self._watch == COLLISION or clearance < 0.0:
                self._margin = clearance
            if clearance < 0.0:
                return COLLISION, detail
        self._trial = (p_e, t)
        return None

    def _land_on_limit(self, f: float, failure: tuple[str, str]) -> Vec | None:
        """Shorten the step to the limit the geometry allows (a contact on its face's
        boundary, R' k reaching 1, a singular point, tangent faces, a guard's zero
        clearance), commit it, and stop.

        At most MAX_TRIALS cycles in all (:func:`~cadcnc.interp.landing.land`: regula falsi
        on the failing rule's margin, bisection for yes/no rules), to LANDING_TOL of step
        where the trials allow it; the reason reported is the one found next to the limit.
        Only trials that pass every check are committed.
        """
        state = {"failure": failure, "kept": False}

        def trial(s: float) -> tuple[bool, float, bool]:
            self._watch = state["failure"][0]
            found = self._try(s * f)
            if found is None:
                self._keep_trial()
                state["kept"] = True
                return True, self._margin, False
            changed = found[0] != state["failure"][0]
            state["failure"] = found
            return False, self._margin, changed

        margin_hi = self._margin
        lo, used = land(trial, self._state_margin(failure[0]), margin_hi, MAX_TRIALS - 1,
                        LANDING_TOL / f)
        self._watch = None
        self.landing_trials = used + 1
        reason, detail = state["failure"]
        if lo * f < LANDING_TOL or not state["kept"]:
            self._stop(reason, detail + " (no step possible from the current point)")
            return None
        dp = self._commit_kept(lo * f)
        self._stop(reason, detail)
        return dp

    def _keep_trial(self) -> None:
        """Keep the trial that just passed (the landing commits the last one kept)."""
        self._kept = (*self._trial, self._n1.copy(), self._n2.copy())

    def _commit_kept(self, f: float) -> Vec:
        p_e, t, self._n1, self._n2 = self._kept
        return self._commit(p_e, t, f)

    def _state_margin(self, rule: str) -> float:
        """The margin of ``rule`` at the current point (the landing's s = 0), NaN if none."""
        c1, c2 = self.c1, self.c2
        if rule == SINGULAR:
            return min(c1.singularity, c2.singularity) - self.tol.near_singular
        if rule == DIVERGED:
            return self.tol.diverged - max(norm(sub(self.p, c.centre())) for c in (c1, c2))
        if rule == CURVATURE:
            t = self._tr.t
            return 1.0 - max(c.offset * c.curvature(t) for c in (c1, c2))
        if rule == COLLISION:
            return self.guard.margin(self.p)[0]
        return math.nan

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
        # not before twice the step and twice the end tolerance: steps of a few nm (a
        # short servo period from rest) would otherwise find a closed path's end at once
        if end is None or self.travelled < 2.0 * max(f, self.tol.end_reached):
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
        """Step until stopped; ``progress(cycles, 0, "<travelled> mm")`` (the package's
        :class:`~cadcnc.core.progress.Progress`, total unknown) every ``every`` cycles."""
        while self.step() is not None:
            if progress is not None and self.cycles % every == 0:
                progress(self.cycles, 0, travelled_text(self.travelled))
        return self
