"""One guide plane's pass over the selected faces: the paper's guide-surface interpolation.

The ball (offset R' = job.tool.offset) touches a selected face and its centre stays on a
vertical guide plane (offsets (R', 0): the plane carries the centre). Planning
(:mod:`.finish_crossings`): where the plane's offset curve crosses the boundary of each
selected face, exactly (contact on the edge, centre on the plane, Brent to 1e-13 of the
edge parameter). Each entry into the selected region from outside starts a chain of cuts:

- on a face, the stepper (compiled kernel where it applies) runs from the entry to the
  face's next exit along the travel, given as its end point: it lands exactly on it
  (else on the face's boundary, within the stepper's landing);
- across an edge to another selected face (:mod:`.finish_transitions`): a tangent edge
  is crossed without stopping, a convex edge rolled over (centre on the arc around the
  edge, in the plane, at the cycle step), a concave edge passed at the tri-tangent point
  (the face's cut ends there, the next starts there); consecutive cuts chain exactly
  (the next cut's first point is the previous cut's last);
- the guard (default: :class:`PassSetup`, one
  :class:`~cadcnc.guard.clearance.ClearanceGuard` per selected face, every other face
  of the part a third face, shank included) stops a cut on ``collision``, landed tangent;
  the pass resumes where the plane's curve is clear again (found by running on without
  the guard, landed back on the clearance's zero), and the stretch between is skipped.

Travel: along +plane.direction, or -direction with ``reverse`` (interpolated from the
other end, not the same points backwards). Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Sequence

import numpy as np

from ...errors import CadcncError, GeometryError
from ...geometry.part import Part
from ...interp.cycle import BOUNDARY, COLLISION, END
from ...interp.stepper import Stepper, Tangency
from ...job import Job, PairPath
from ...program.program import FAILED, STOPPED_SHORT, CutSegment, Skipped
from ...program.toolpath import Toolpath, toolpath_from_record
from .check import pass_problems
from .crossings import Crossing, pass_tangent
from .setup import PassSetup, guide_face, pass_setup
from .polish import polish
from .transitions import CONCAVE, CONVEX, TANGENT, transition

REACHED = 1e-3
"""mm: a cut stopping on its face's boundary this near the planned exit has reached it."""
RESUME_STEPS = 4     # cycles allowed to the run landing back on a clearance's zero
SHORTEST = 2e-6      # mm: the step of a piece shorter than two steps is a third of it
NO_PIECE = 1e-4
"""mm: a piece of a face this short between its entry and exit (a plane grazing a corner)
is not cut: the chain goes on from its exit (the chord's sag would be below 1e-9 mm)."""


@dataclass(frozen=True)
class GuidePlane:
    """A vertical guide plane carrying the ball centre: points p with
    dot(p, normal) == offset. angle A (degrees) is the pass direction's angle to +X:
    direction = (cos A, sin A, 0), normal = (-sin A, cos A, 0)."""

    angle: float    # degrees
    offset: float   # mm, along normal

    @property
    def direction(self) -> np.ndarray:
        """(3,) unit pass direction."""
        a = math.radians(self.angle)
        return np.array([math.cos(a), math.sin(a), 0.0])

    @property
    def normal(self) -> np.ndarray:
        """(3,) unit normal of the plane."""
        a = math.radians(self.angle)
        return np.array([-math.sin(a), math.cos(a), 0.0])


@dataclass
class PassResult:
    """The cuts of one plane in travel order, and what of its section was not cut."""

    cuts: list[CutSegment] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)


def pass_cuts(part: Part, faces: Sequence[int], plane: GuidePlane, job: Job, *,
              reverse: bool = False, guard=None) -> PassResult:
    """Every cut of one guide plane over the selected ``faces`` (1-based numbers of
    ``part``): the ball (radius job.tool.offset = R') touches the selected faces and its
    centre stays on ``plane`` (the paper's guide-surface interpolation, offsets (R', 0)).
    Each cut starts exactly where the plane's offset curve enters the selected region,
    crosses tangent-continuous edges between selected faces without stopping, rolls over
    convex edges between selected faces (centre on the arc around the edge, in the plane,
    at the cycle step), goes through the tri-tangent point at concave edges between
    selected faces, and stops landed at the boundary of the selected region or on
    `collision` with an unselected face (guard). Gaps (holes, islands) give several cuts.

    ``guard``: None for the default (:func:`pass_setup`'s, built once per part, faces
    and tool), a :class:`PassSetup` (its per-face guards), False for none, or any object
    with ``margin(p)`` used for every cut.
    """
    if isinstance(guard, PassSetup):
        setup, fixed = guard, None
    else:
        setup = pass_setup(part, faces, job)
        fixed = guard
    return _Pass(setup, plane, job, reverse, fixed).run()


class _Pass:
    """The planning and cutting of one plane (see the module doc)."""

    def __init__(self, setup: PassSetup, plane: GuidePlane, job: Job, reverse: bool, guard):
        self.setup, self.plane, self.job = setup, plane, job
        self.sense = -1.0 if reverse else 1.0
        self.travel = self.sense * plane.direction
        self.nrm = plane.normal
        self.origin = plane.offset * plane.normal
        self.y_axis = np.cross(plane.normal, plane.direction)
        self.guide = guide_face(plane, setup.size, job)
        self.fixed_guard = guard
        self.crossings = {f: sorted(e.crossings(self.nrm, plane.offset, self.travel),
                                    key=lambda c: c.s) for f, e in setup.edges.items()}
        self.result = PassResult()
        self.accounted: list[tuple[float, float]] = []   # s stretches skipped with a reason

    # -- helpers ------------------------------------------------------------------------
    def guard(self, face: int):
        if self.fixed_guard is False:
            return None
        return self.fixed_guard if self.fixed_guard is not None else self.setup.guard(face)

    def tangency(self, p, uv) -> Tangency:
        """The stepper's state at centre p (on the plane) with face parameters uv."""
        d = np.asarray(p, float) - self.origin
        return Tangency(tuple(map(float, p)), (float(uv[0]), float(uv[1])),
                        (float(d @ self.plane.direction), float(d @ self.y_axis)))

    def where(self, face: int) -> str:
        return f"plane at angle {self.plane.angle:g} deg, offset {self.plane.offset:.4f} mm, " \
               f"face {face}"

    def skip(self, face: int, reason: str, detail: str, stretch=None) -> None:
        """Record a skipped stretch; ``stretch`` (two points, mm) its ends when known."""
        self.result.skipped.append(Skipped((face, None), reason,
                                           f"{self.where(face)}: {detail}"))
        if stretch is not None:
            self.accounted.append(tuple(float(np.dot(p, self.travel)) for p in stretch))

    # -- the pass -----------------------------------------------------------------------
    def run(self) -> PassResult:
        entries = sorted((c for cs in self.crossings.values() for c in cs if c.entry),
                         key=lambda c: c.s)
        for c in entries:
            if c.used:
                continue
            c.used = True
            try:
                self.chain(c.face, self.tangency(c.point, c.uv))
            except CadcncError as e:
                self.skip(c.face, FAILED, f"from {_xyz(c.point)}: {e}")
        problems = pass_problems(self.result.cuts, self.crossings, self.accounted,
                                 self.travel)
        if problems:   # never a wrong path: the plane's cuts are dropped, the plane listed
            self.result.cuts = []
            self.result.skipped.append(Skipped((None, None), FAILED, (
                f"plane at angle {self.plane.angle:g} deg, offset {self.plane.offset:.4f} "
                f"mm{' (reversed)' if self.sense < 0 else ''} failed its self-check, not "
                f"cut: {'; '.join(problems)}")))
        return self.result

    def next_exit(self, face: int, p) -> Crossing | None:
        """The first exit of ``face`` ahead of the centre ``p`` (mm) along the travel: the
        least s not behind p's, the nearest to p among equal s (a wall climbed)."""
        s = float(np.dot(p, self.travel))
        ahead = [c for c in self.crossings[face] if not c.entry and not c.used
                 and c.s >= s - 1e-9]
        return min(ahead, key=lambda c: (round(c.s, 9), float(np.linalg.norm(c.point - p))),
                   default=None)

    def chain(self, face: int, start: Tangency) -> None:
        """Cuts from ``start`` on ``face`` across selected faces until the chain ends."""
        while True:
            exit_ = self.next_exit(face, np.asarray(start.p))
            step = transition(self, face, exit_) if exit_ is not None else None
            end = step.end if step is not None else None
            last = self.piece(face, start, end)
            if last is None:
                return
            if step is None or step.kind is None:
                return
            if step.end is None or np.linalg.norm(np.subtract(last.p, step.end.p)) > REACHED:
                return
            exit_.used = True
            if step.entry is not None:
                step.entry.used = True
            if step.kind == CONVEX:
                arc = step.arc(last.p)
                self.result.cuts.append(CutSegment(arc, at_limit=True))
                start = self.tangency(arc.points[-1], step.next_uv)
            elif step.kind in (TANGENT, CONCAVE):
                start = self.tangency(last.p, step.next_uv)
            face = step.next_face

    def piece(self, face: int, start: Tangency, end: Tangency | None) -> Tangency | None:
        """Cut ``face`` from ``start`` towards ``end`` (its planned exit), resuming past
        collisions; the last state when the cuts reached ``end`` (None otherwise)."""
        guard = self.guard(face)
        pos, exact = start, True
        if end is not None and np.linalg.norm(np.subtract(end.p, start.p)) <= NO_PIECE:
            return end
        while True:
            tp = self.run_stepper(face, pos, end, guard)
            self.exact(face, tp, guard, exact)
            if len(tp) > 1:
                self.result.cuts.append(CutSegment(
                    tp, at_limit=tp.stop_reason in (END, BOUNDARY, COLLISION)))
            last = _last_state(tp)
            if tp.stop_reason == END:
                return last
            if tp.stop_reason == BOUNDARY:
                near = end is not None and np.linalg.norm(
                    np.subtract(last.p, end.p)) <= REACHED
                if near or end is None:
                    return last if near else None
                self.skip(face, STOPPED_SHORT, f"the cut from {_xyz(pos.p)} stopped on the "
                          f"face's boundary at {_xyz(last.p)}, short of its planned exit "
                          f"{_xyz(end.p)}", (last.p, end.p))
                return None
            if tp.stop_reason != COLLISION:
                self.skip(face, STOPPED_SHORT, f"the cut from {_xyz(pos.p)} {tp.partial_reason}",
                          (last.p, end.p) if end is not None else None)
                return None
            pos, exact = self.clear_again(face, last, end, guard, tp.stop_detail), False
            if pos is None:
                return None

    def exact(self, face: int, tp: Toolpath, guard, keep_first: bool) -> None:
        """Move the cut's points onto the exact offset curve (:mod:`.finish_polish`), in
        place; an exact start (an entry, a transition) and an end landed on are kept as
        they are. A point landed on a guard's zero (first after a resume, last after a
        collision) that the move made negative is put back on the zero, on the curve."""
        surface, rp = self.setup.surfaces[face], self.job.tool.offset
        c, uv, r, n = polish(surface, rp, self.nrm, self.plane.offset, tp.points,
                             tp.uv[:, 0])
        keep = [0] if keep_first else []
        if tp.stop_reason == END:
            keep.append(len(tp) - 1)
        for k in keep:
            c[k], uv[k], r[k], n[k] = tp.points[k], tp.uv[k, 0], tp.contacts[k, 0], \
                tp.normals[k, 0]
        landed = [] if keep_first else [(0, 1)]
        if tp.stop_reason == COLLISION:
            landed.append((len(tp) - 1, len(tp) - 2))
        for k, clear in landed if guard is not None and len(tp) > 1 else ():
            found = self.land_exact(surface, c[clear], 2.0 * c[k] - c[clear], uv[k], guard)
            if found is not None:
                c[k], uv[k], r[k], n[k] = found
        tp.points[:] = c
        tp.contacts[:, 0], tp.contacts[:, 1], tp.normals[:, 0], tp.uv[:, 0] = r, c, n, uv
        d = c - self.origin
        tp.uv[:, 1] = np.stack([d @ self.plane.direction, d @ self.y_axis], axis=1)
        tp.steps[1:] = np.linalg.norm(np.diff(c, axis=0), axis=1)

    def land_exact(self, surface, clear: np.ndarray, beyond: np.ndarray, uv, guard):
        """The point of the exact offset curve between ``clear`` and ``beyond`` (mm;
        ``beyond`` one step past a landed point) where the guard's clearance reaches 0, on
        its clear side (bisection to 1e-10 of the chord): (centre, uv, contact, normal),
        or None when the curve is clear up to ``beyond``."""
        def on_curve(x: float):
            return polish(surface, self.job.tool.offset, self.nrm, self.plane.offset,
                          (clear + x * (beyond - clear))[None], np.asarray(uv)[None])

        best = on_curve(1.0)
        if guard.margin(tuple(best[0][0]))[0] >= 0.0:
            return None
        lo, hi, best = 0.0, 1.0, on_curve(0.0)
        for _ in range(34):
            mid = 0.5 * (lo + hi)
            found = on_curve(mid)
            if guard.margin(tuple(found[0][0]))[0] >= 0.0:
                lo, best = mid, found
            else:
                hi = mid
        return tuple(a[0] for a in best)

    def clear_again(self, face: int, at: Tangency, end, guard, why: str) -> Tangency | None:
        """Where the plane's curve on ``face`` past a collision at ``at`` is clear again:
        run on without the guard, take the first clear point after a hit, and land back
        from it on the clearance's zero. Skips the stretch in between (``collision``)."""
        free = self.run_stepper(face, at, end, None)
        margins = [guard.margin(tuple(p))[0] for p in free.points[1:]]
        hit = False
        for k, m in enumerate(margins, 1):
            hit = hit or m < 0.0
            if m >= 0.0 and (hit or k == len(margins)):
                break
        else:
            k = None
        if k is None or not hit:
            self.skip(face, COLLISION, f"from {_xyz(at.p)} to {_xyz(free.points[-1])} "
                      f"({why})", (at.p, end.p if end is not None else free.points[-1]))
            return None
        clear = _state(free, k)
        back = self.run_stepper(face, clear, None, guard, backwards=True,
                                max_cycles=RESUME_STEPS)
        resume = _last_state(back) if back.stop_reason == COLLISION else clear
        self.skip(face, COLLISION, f"from {_xyz(at.p)} to {_xyz(resume.p)} ({why})",
                  (at.p, resume.p))
        return resume

    def run_stepper(self, face: int, start: Tangency, end: Tangency | None, guard, *,
                    backwards: bool = False, max_cycles: int = 1_000_000) -> Toolpath:
        """The stepper on ``face`` and the guide plane from ``start`` (to ``end``)."""
        job = self.job
        surface = self.setup.surfaces[face]
        try:
            tau = pass_tangent(surface.normal(*start.uv1), self.travel)
        except ValueError as e:
            raise GeometryError(f"at {_xyz(start.p)} on face {face}: {e}") from None
        if backwards:
            tau = -tau
        feed = job.feed
        if end is not None:   # the stepper lands on an end only after two steps
            gap = float(np.linalg.norm(np.subtract(end.p, start.p)))
            feed = min(feed, max(gap / 3.0, SHORTEST) * 60.0 / job.period)
        stepper = Stepper(surface, self.guide, (job.tool.offset, 0.0), start, feed=feed,
                          period=job.period, direction=tuple(tau), end=end,
                          tol=job.tolerances, max_cycles=max_cycles, guard=guard)
        stepper.run()
        op = PairPath(faces=(face, None), offsets=(None, 0.0), start=start.p, edge=None)
        return toolpath_from_record(stepper.record, replace(job, operation=op),
                                    stepper.stop_reason, stepper.stop_detail)


def _state(tp: Toolpath, k: int) -> Tangency:
    return Tangency(tuple(map(float, tp.points[k])), tuple(map(float, tp.uv[k, 0])),
                    tuple(map(float, tp.uv[k, 1])))


def _last_state(tp: Toolpath) -> Tangency:
    return _state(tp, len(tp) - 1)


def _xyz(p) -> str:
    return "(" + ", ".join(f"{float(v):.3f}" for v in p) + ")"
