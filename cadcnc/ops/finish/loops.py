"""One waterline level: every closed loop and open piece of the ball centre at height z.

Waterline finishing is the guide-surface interpolation of raster passes
(:mod:`.passes`) with a horizontal guide plane z = const (offsets (R', 0)): the ball
touches a selected face while its centre stays at height z, and the cut is the section of
the face's offset surface by that plane. At each level, per selected face:

- **open pieces** start and end exactly where the level's offset curve crosses the face's
  boundary (:class:`~cadcnc.ops.finish.crossings.FaceEdges`: contact on the edge, centre
  at z, Brent to 1e-13 of the edge parameter), each entry paired with its exit by OCCT's
  section of the face's offset (:mod:`cadcnc.geometry.offset_section`): the wire whose
  ends they are. An entry no wire claims is still cut, to wherever the face ends;
- **closed loops** are seeded at a point of each closed wire of that section (the one
  nearest the tool), the contact found by OCCT's projection and put exactly on the curve
  (:func:`~cadcnc.ops.finish.polish.polish`), and run once around (``closed``).

The travel is ``climb`` (the material on the cutter's right, clockwise around a boss
seen from +Z, for a spindle turning clockwise) or ``conventional``: the centre's tangent
is -+(z x n) normalised (n the outward normal). The guard, the resumes past a collision
and the exact points are the raster passes' (:mod:`.resume`, :mod:`.polish`). Pieces are
taken nearest first from where the tool is. **Self-check**: every point of OCCT's section
(about 0.5 mm apart) lies within one step of a cut point, or where the guard refuses the
ball; a level that fails is not cut (``failed``). Lengths mm.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial import cKDTree

from ...core.errors import CadcncError
from ...core.job import Job, PairPath
from ...geometry.offset_section import SectionWire, section_wires
from ...interp.compiled import new_stepper
from ...interp.cycle import BOUNDARY, CLOSED, COLLISION, END
from ...interp.stepper import Tangency
from ...program.program import FAILED, STOPPED_SHORT, CutSegment, Skipped
from ...program.toolpath import Toolpath, toolpath_from_record
from .pass_setup import PassSetup, guide_face
from .polish import polish
from .resume import PASS_CYCLES, clear_again, free_run, last_state, xyz

Z = np.array([0.0, 0.0, 1.0])
X = np.array([1.0, 0.0, 0.0])
SIDES = ("climb", "conventional")
MATCH_MM = 1e-3
"""mm: a section wire's end this near a boundary crossing ends there."""
MAX_RESUMES = 1000


def loop_tangent(side: str):
    """The unit tangent t(n) (3,) of a level's loop at a contact of outward normal n
    (module doc); ValueError where n is vertical (a horizontal spot: no loop)."""
    sign = -1.0 if side == "climb" else 1.0

    def tangent(n: np.ndarray) -> np.ndarray:
        t = sign * np.array([-n[1], n[0], 0.0])
        length = float(np.linalg.norm(t))
        if length < 1e-12:   # no direction (a horizontal normal's xy is 0)
            raise ValueError("the face is horizontal here")
        return t / length
    return tangent


@dataclass(frozen=True)
class Level:
    """The horizontal guide plane z = ``offset`` (mm) carrying the ball centre."""

    offset: float
    normal: np.ndarray = field(default_factory=lambda: Z.copy())
    direction: np.ndarray = field(default_factory=lambda: X.copy())


@dataclass
class LevelResult:
    """The cuts of one level in cutting order, what was not cut, the stepper cycles run,
    and OCCT's section wires of each face (``wires``: face -> list of SectionWire)."""

    cuts: list[CutSegment] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    cycles: int = 0
    wires: dict = field(default_factory=dict)


@dataclass
class _Piece:
    face: int
    start: Tangency | None      # open: the entry; closed: None (seeded near the tool)
    end: Tangency | None
    wire: SectionWire | None


def level_cuts(setup: PassSetup, offset_faces: dict, z: float, job: Job, side: str, *,
               near=None, beat=None) -> LevelResult:
    """Every cut of the level at height ``z`` (mm) over ``setup``'s faces (module doc);
    ``offset_faces``: face -> its OCCT offset face (R'); ``near`` (3,): where the tool is
    (the first piece is the nearest to it)."""
    return _Level(setup, offset_faces, z, job, side, near, beat).run()


class _Level:
    """The planning and cutting of one level (see the module doc); the interface of
    :mod:`.resume`'s functions (``job``, ``nrm``, ``plane``, ``run_stepper``, ``skip``,
    ``free_run``)."""

    def __init__(self, setup, offset_faces, z, job, side, near, beat):
        self.setup, self.job, self.side = setup, job, side
        self.plane, self.nrm = Level(float(z)), Z
        self.tangent = loop_tangent(side)
        self.guide = guide_face(self.plane, setup.guide_size(self.plane), job)
        self.offset_faces = offset_faces
        self.here = np.asarray(near, float) if near is not None else None
        self.beat = beat or (lambda text: False)
        self.result = LevelResult()

    def where(self, face: int) -> str:
        return f"level z {self.plane.offset:.4f} mm, face {face}"

    def skip(self, face: int, reason: str, detail: str, stretch=None) -> None:
        self.result.skipped.append(Skipped((face, None), reason,
                                           f"{self.where(face)}: {detail}"))

    def state(self, p, uv) -> Tangency:
        p = tuple(map(float, p))
        return Tangency(p, (float(uv[0]), float(uv[1])), (p[0], p[1]))

    # -- planning -----------------------------------------------------------------------
    def pieces(self) -> list[_Piece]:
        out = []
        z = self.plane.offset
        for face in self.setup.faces:
            crossings = self.setup.edges[face].crossings(Z, z, X, tangent=self.tangent)
            wires = section_wires([self.offset_faces[face]], z)
            self.result.wires[face] = wires
            unused = list(crossings)
            for w in wires:
                if w.closed:
                    out.append(_Piece(face, None, None, w))
                    continue
                ends = [self._nearest(unused, p) for p in (w.points[0], w.points[-1])]
                entry = next((c for c in ends if c is not None and c.entry), None)
                exit_ = next((c for c in ends if c is not None and not c.entry), None)
                if entry is None or exit_ is None:
                    self.skip(face, FAILED, f"OCCT's section wire from {xyz(w.points[0])} "
                              f"to {xyz(w.points[-1])} does not end on crossings of the "
                              "face's boundary")
                    continue
                unused = [c for c in unused if c is not entry and c is not exit_]
                out.append(_Piece(face, self.state(entry.point, entry.uv),
                                  self.state(exit_.point, exit_.uv), w))
            for c in unused:   # an entry OCCT's section did not see: cut it anyway
                if c.entry:
                    out.append(_Piece(face, self.state(c.point, c.uv), None, None))
        return out

    @staticmethod
    def _nearest(crossings, p):
        best = min(crossings, key=lambda c: float(np.linalg.norm(c.point - p)), default=None)
        if best is None or np.linalg.norm(best.point - p) > MATCH_MM:
            return None
        return best

    def seed(self, piece: _Piece) -> Tangency:
        """A start on the closed wire of ``piece``, nearest the tool, exact on the curve."""
        pts = piece.wire.points
        k = 0 if self.here is None else int(np.argmin(np.linalg.norm(pts - self.here, axis=1)))
        surface = self.setup.surfaces[piece.face]
        u, w, _ = surface.project(pts[k])
        c, uv, _, _ = polish(surface, self.job.tool.offset, Z, self.plane.offset,
                             pts[k][None], np.array([[u, w]]))
        return self.state(c[0], uv[0])

    # -- cutting ------------------------------------------------------------------------
    def run(self) -> LevelResult:
        todo = self.pieces()
        while todo:
            def distance(pc: _Piece) -> float:
                if self.here is None:
                    return 0.0
                pts = pc.wire.points if pc.start is None else np.array([pc.start.p])
                return float(np.linalg.norm(pts - self.here, axis=1).min())
            piece = todo.pop(min(range(len(todo)), key=lambda k: distance(todo[k])))
            try:
                self.cut(piece)
            except CadcncError as e:
                self.skip(piece.face, FAILED, str(e))
        problems = self.check()
        if problems:
            self.result.cuts = []
            self.result.skipped.append(Skipped((None, None), FAILED, (
                f"level z {self.plane.offset:.4f} mm failed its self-check, not cut: "
                + "; ".join(problems))))
        return self.result

    def cut(self, piece: _Piece) -> None:
        """Cut one piece from its start (or seed) to its end (or once around)."""
        face, guard = piece.face, self.setup.guard(piece.face)
        closed = piece.start is None
        pos = self.seed(piece) if closed else piece.start
        end = piece.end
        first = closed
        for _ in range(MAX_RESUMES):
            self.beat(lambda: f"{self.where(face)}: cutting from {xyz(pos.p)}")
            tp = self.run_stepper(face, pos, end, guard, closed=first)
            if first:
                end = pos   # after a resume, a closed loop ends at its seed
            first = False
            self.exact(face, tp)
            if len(tp) > 1:
                self.result.cuts.append(CutSegment(
                    tp, at_limit=tp.stop_reason in (END, BOUNDARY, COLLISION)))
                self.here = tp.points[-1]
            if tp.stop_reason in (END, CLOSED) or (tp.stop_reason == BOUNDARY
                                                   and piece.end is None):
                return
            last = last_state(tp)
            if tp.stop_reason != COLLISION:
                self.skip(face, STOPPED_SHORT, f"the cut from {xyz(pos.p)} "
                          f"{tp.partial_reason}")
                return
            pos = clear_again(self, face, last, end, guard, tp.stop_detail)
            if pos is None:
                return
        self.skip(face, STOPPED_SHORT, f"stopped on collision {MAX_RESUMES} times")

    def exact(self, face: int, tp: Toolpath) -> None:
        """The cut's points moved onto the exact offset curve (:func:`.polish.polish`),
        its first point and a landed last point kept (exact already)."""
        if len(tp) < 2:
            return
        surface = self.setup.surfaces[face]
        inner = slice(1, len(tp) - (1 if tp.stop_reason in (END, CLOSED) else 0))
        c, uv, r, n = polish(surface, self.job.tool.offset, Z, self.plane.offset,
                             tp.points[inner], tp.uv[inner, 0])
        tp.points[inner], tp.uv[inner, 0] = c, uv
        tp.contacts[inner, 0], tp.contacts[inner, 1], tp.normals[inner, 0] = r, c, n
        tp.uv[:, 1] = tp.points[:, :2]
        tp.steps[1:] = np.linalg.norm(np.diff(tp.points, axis=0), axis=1)

    def free_run(self, face: int, at: Tangency, end, guard):
        """See :func:`.resume.free_run`."""
        return free_run(self, face, at, end, guard)

    def run_stepper(self, face: int, start: Tangency, end: Tangency | None, guard, *,
                    backwards: bool = False, max_cycles: int = PASS_CYCLES,
                    closed: bool = False) -> Toolpath:
        """The stepper on ``face`` and the level's plane from ``start`` (to ``end``, or
        once around with ``closed``)."""
        job, surface = self.job, self.setup.surfaces[face]
        tau = self.tangent(surface.normal(*start.uv1))
        if backwards:
            tau = -tau
        stepper = new_stepper(surface, self.guide, (job.tool.offset, 0.0), start, feed=job.feed,
                          period=job.period, direction=tuple(tau),
                          end=None if closed else end, closed=closed,
                          tol=job.tolerances, max_cycles=max_cycles, guard=guard)
        stepper.run()
        self.result.cycles += stepper.cycles
        op = PairPath(faces=(face, None), offsets=(None, 0.0), start=start.p, edge=None)
        return toolpath_from_record(stepper.record, replace(job, operation=op),
                                    stepper.stop_reason, stepper.stop_detail)

    def check(self) -> list[str]:
        """The self-check (module doc): sentences of what failed, [] when none."""
        pts = [c.points for c in self.result.cuts]
        tree = cKDTree(np.vstack(pts)) if pts else None
        reach = max(self.job.step, 1e-3) * 1.01 + 1e-6   # mm: a step, 1 % and round-off
        problems = []
        for face, wires in self.result.wires.items():
            guard = self.setup.guard(face)
            for w in wires:
                d = tree.query(w.points)[0] if tree is not None else np.full(len(w.points),
                                                                             np.inf)
                for p in w.points[d > reach]:
                    if guard is not None and guard.margin(tuple(p))[0] < 0.0:
                        continue
                    problems.append(f"face {face}: the section point {xyz(p)} is not cut")
                    break
        return problems
