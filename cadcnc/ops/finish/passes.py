"""One guide plane's pass over the selected faces: the paper's guide-surface interpolation.

The ball (offset R' = job.tool.offset) touches a selected face and its centre stays on a
vertical guide plane (offsets (R', 0): the plane carries the centre). Planning
(:mod:`.crossings`): where the plane's offset curve crosses the boundary of each
selected face, exactly (contact on the edge, centre on the plane, Brent to 1e-13 of the
edge parameter). Each entry into the selected region from outside starts a chain of cuts:

- on a face, the stepper (compiled kernel where it applies) runs from the entry to the
  face's next exit along the travel, given as its end point: it lands exactly on it
  (else on the face's boundary, within the stepper's landing);
- across an edge to another selected face (:mod:`.transitions`): a tangent edge
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

from ...core.errors import CadcncError, GeometryError
from ...core.job import Job, PairPath
from ...geometry.part import Part
from ...interp.compiled import new_stepper
from ...interp.cycle import BOUNDARY, COLLISION, END
from ...interp.stepper import Tangency
from ...program.program import FAILED, STOPPED_SHORT, CutSegment, Skipped
from ...program.toolpath import Toolpath, toolpath_from_record
from .check import along_pass, pass_problems
from .crossings import Crossing, pass_tangent
from .pass_setup import PassSetup, guide_face, pass_setup
from .polish import polish
from .resume import PASS_CYCLES, clear_again, free_run, land_exact, last_state, xyz
from .transitions import CONCAVE, CONVEX, TANGENT, transition

REACHED = 1e-3
"""mm: a cut stopping on its face's boundary this near the planned exit has reached it."""
SHORTEST = 2e-6      # mm: the step of a piece shorter than two steps is a third of it
JOIN_MM = 1e-6
"""mm: a cut starting this near another's end continues it (as the program's links)."""
NO_PIECE = 1e-4
"""mm: a piece of a face this short between its entry and exit (a plane grazing a corner)
is not cut: the chain goes on from its exit (the chord's sag would be below 1e-9 mm)."""
MAX_RESUMES = 1000
"""Collisions one piece of a face may resume past; more stop the piece with a reason."""
BEAT_CYCLES = 256
"""The stepper tells the pass's heartbeat every this many cycles."""


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
    cycles: int = 0
    """Stepper cycles the pass ran (re-runs past collisions included)."""


def pass_cuts(part: Part, faces: Sequence[int], plane: GuidePlane, job: Job, *,
              reverse: bool = False, guard=None, beat=None) -> PassResult:
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
    with ``margin(p)`` used for every cut. ``beat(text)``: told while the pass runs (every
    BEAT_CYCLES stepper cycles and at every piece), e.g. a
    :class:`~cadcnc.core.work_limits.Heartbeat`'s ``beat``, which reports when due.
    """
    if isinstance(guard, PassSetup):
        setup, fixed = guard, None
    else:
        setup = pass_setup(part, faces, job)
        fixed = guard
    return _Pass(setup, plane, job, reverse, fixed, beat).run()


class _Pass:
    """The planning and cutting of one plane (see the module doc)."""

    def __init__(self, setup: PassSetup, plane: GuidePlane, job: Job, reverse: bool, guard,
                 beat=None):
        self.setup, self.plane, self.job = setup, plane, job
        self.beat = beat or (lambda text: False)
        self.cycles = 0      # stepper cycles run by this pass, re-runs included
        self.sense = -1.0 if reverse else 1.0
        self.travel = self.sense * plane.direction
        self.nrm = plane.normal
        self.origin = plane.offset * plane.normal
        self.y_axis = np.cross(plane.normal, plane.direction)
        self.guide = guide_face(plane, setup.guide_size(plane), job)
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
        # in their order along the pass, not by s alone: on a wall descended the entry at
        # its top comes first, so its chain goes on into the face below through that face's
        # entry at the wall's foot (equal s) before that entry could start a second chain
        entries = [c for c in along_pass([c for cs in self.crossings.values() for c in cs],
                                         self.travel) if c.entry]
        for c in entries:
            if c.used:
                continue
            c.used = True
            try:
                self.chain(c.face, self.tangency(c.point, c.uv))
            except CadcncError as e:
                self.skip(c.face, FAILED, f"from {xyz(c.point)}: {e}")
        self.result.cuts = chained_order(self.result.cuts)
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
                 and c.s >= s - 1e-9]   # mm: round-off of s
        return min(ahead, key=lambda c: (round(c.s, 9), float(np.linalg.norm(c.point - p))),
                   default=None)

    def exit_at(self, face: int, p) -> Crossing | None:
        """An unused exit of ``face`` within REACHED of the centre ``p`` (mm), or None."""
        near = [c for c in self.crossings[face] if not c.entry and not c.used
                and np.linalg.norm(c.point - np.asarray(p)) <= REACHED]
        return min(near, key=lambda c: float(np.linalg.norm(c.point - np.asarray(p))),
                   default=None)

    def cut_near(self, face: int, p) -> bool:
        """Whether a cut of this pass on ``face`` already passes within a step of ``p``."""
        step = max(self.job.step, REACHED)
        return any(cut.path.faces[0] == face and float(np.linalg.norm(
            cut.points - np.asarray(p), axis=1).min()) <= step for cut in self.result.cuts)

    def chain(self, face: int, start: Tangency) -> None:
        """Cuts from ``start`` on ``face`` across selected faces until the chain ends.
        Bounded: every turn consumes an exit crossing. The exit a cut reached is the one
        it landed on (the crossings' order along the pass), not always the first in s."""
        for _ in range(sum(len(cs) for cs in self.crossings.values()) + 1):
            exit_ = self.next_exit(face, np.asarray(start.p))
            step = transition(self, face, exit_) if exit_ is not None else None
            end = step.end if step is not None else None
            self.landed = None
            last = self.piece(face, start, end)
            if last is None:
                return
            if self.landed is not None and self.landed is not exit_:
                exit_ = self.landed   # landed on another exit of the face: go on from it
                step = transition(self, face, exit_)
                if step.kind == CONCAVE:   # its tri-tangent point was not where we stopped
                    exit_.used = True
                    return
            if step is None or step.kind is None:
                if exit_ is not None and self.landed is exit_:
                    exit_.used = True
                return
            if step.end is None or np.linalg.norm(np.subtract(last.p, step.end.p)) > REACHED:
                return
            exit_.used = True
            if step.entry is not None:
                step.entry.used = True
            if step.kind == CONCAVE:   # F's curve past the tri-tangent point is in G's shadow
                self.accounted.append(tuple(float(np.dot(q, self.travel))
                                            for q in (last.p, exit_.point)))
                if self.cut_near(step.next_face, last.p):
                    return   # G's curve from there was cut already (by an earlier chain)
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
        for _ in range(MAX_RESUMES):
            self.beat(lambda: f"{self.where(face)}: cutting from {xyz(pos.p)}")
            tp = self.run_stepper(face, pos, end, guard)
            self.exact(face, tp, guard, exact)
            if len(tp) > 1:
                self.result.cuts.append(CutSegment(
                    tp, at_limit=tp.stop_reason in (END, BOUNDARY, COLLISION)))
            last = last_state(tp)
            if tp.stop_reason == END:
                return last
            if tp.stop_reason == BOUNDARY:
                near = end is not None and np.linalg.norm(
                    np.subtract(last.p, end.p)) <= REACHED
                if not near:   # another exit of the face, reached first along the pass
                    self.landed = self.exit_at(face, last.p)
                    near = self.landed is not None
                if near or end is None:
                    return last if near else None
                self.skip(face, STOPPED_SHORT, f"the cut from {xyz(pos.p)} stopped on the "
                          f"face's boundary at {xyz(last.p)}, short of its planned exit "
                          f"{xyz(end.p)}", (last.p, end.p))
                return None
            if tp.stop_reason != COLLISION:
                self.skip(face, STOPPED_SHORT, f"the cut from {xyz(pos.p)} {tp.partial_reason}",
                          (last.p, end.p) if end is not None else None)
                return None
            before = pos
            pos, exact = self.clear_again(face, last, end, guard, tp.stop_detail), False
            if pos is None:
                return None
            if len(tp) <= 1 and np.linalg.norm(np.subtract(pos.p, before.p)) <= SHORTEST:
                self.skip(face, STOPPED_SHORT, f"the pass made no progress at "
                          f"{xyz(pos.p)}: it resumed where it had stopped on collision")
                return None
        self.skip(face, STOPPED_SHORT, f"the cut stopped on collision {MAX_RESUMES} times "
                  f"and resumed past each; stopped at {xyz(pos.p)}",
                  (pos.p, end.p) if end is not None else None)
        return None

    def exact(self, face: int, tp: Toolpath, guard, keep_first: bool) -> None:
        """Move the cut's points onto the exact offset curve (:mod:`.polish`), in
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

    def land_exact(self, surface, clear, beyond, uv, guard):
        """See :func:`.resume.land_exact`."""
        return land_exact(self, surface, clear, beyond, uv, guard)

    def clear_again(self, face: int, at: Tangency, end, guard, why: str) -> Tangency | None:
        """See :func:`.resume.clear_again`."""
        return clear_again(self, face, at, end, guard, why)

    def free_run(self, face: int, at: Tangency, end, guard):
        """See :func:`.resume.free_run`."""
        return free_run(self, face, at, end, guard)

    def run_stepper(self, face: int, start: Tangency, end: Tangency | None, guard, *,
                    backwards: bool = False, max_cycles: int = PASS_CYCLES) -> Toolpath:
        """The stepper on ``face`` and the guide plane from ``start`` (to ``end``)."""
        job = self.job
        surface = self.setup.surfaces[face]
        try:
            tau = pass_tangent(surface.normal(*start.uv1), self.travel)
        except ValueError as e:
            raise GeometryError(f"at {xyz(start.p)} on face {face}: {e}") from None
        if backwards:
            tau = -tau
        feed = job.feed
        if end is not None:   # the stepper lands on an end only after two steps
            gap = float(np.linalg.norm(np.subtract(end.p, start.p)))
            feed = min(feed, max(gap / 3.0, SHORTEST) * 60.0 / job.period)
        stepper = new_stepper(surface, self.guide, (job.tool.offset, 0.0), start, feed=feed,
                          period=job.period, direction=tuple(tau), end=end,
                          tol=job.tolerances, max_cycles=max_cycles, guard=guard)
        where = self.where(face)
        stepper.run(progress=lambda cycles, _total, travelled: self.beat(
            lambda: f"{where}: {self.cycles + cycles} cycles, {travelled}"), every=BEAT_CYCLES)
        self.cycles += stepper.cycles
        self.result.cycles = self.cycles
        op = PairPath(faces=(face, None), offsets=(None, 0.0), start=start.p, edge=None)
        return toolpath_from_record(stepper.record, replace(job, operation=op),
                                    stepper.stop_reason, stepper.stop_detail)


def chained_order(cuts: list[CutSegment]) -> list[CutSegment]:
    """``cuts`` in the order they were made, except that a cut ending exactly (within
    ``JOIN_MM``) where an earlier one starts is moved before it (a wall descended onto
    a stretch an earlier chain reached first): the pass runs on without a link."""
    out = list(cuts)
    for _ in range(len(out)):   # at most one move per cut
        moved = False
        for i in range(len(out)):
            j = next((j for j in range(i + 1, len(out)) if np.linalg.norm(
                out[j].points[-1] - out[i].points[0]) <= JOIN_MM), None)
            if j is not None:
                out.insert(i, out.pop(j))
                moved = True
                break
        if not moved:
            break
    return out
