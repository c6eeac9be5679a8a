"""The program of a face pair: every feasible stretch of its corner, cut and linked.

:func:`program_for_job` is what ``cadcnc path`` runs. Without a start point it finds
every feasible stretch of the pair's shared concave edges (or of edge ``edge`` alone,
and stretch ``stretch`` alone, when the job names them; :mod:`.stretches`), runs the
stepper along each from its start limit to its end limit with the third-face and shank
guard inside it (stop rule ``collision``), and links the cuts (retract, rapid, plunge),
each entered where the tool can get to it (:mod:`cadcnc.ops.entries`; a cut none
reaches is skipped as ``unreachable``).
With a start point it runs one path as :func:`~cadcnc.ops.path.pair_path.path_for_job` does,
except that a start outside every stretch moves to the nearest stretch limit, and the
program's ``notes`` say so. Edges with no feasible position are listed in ``skipped``
with the reason; a cut that stops before its stretch's end is kept and the rest of the
stretch listed as ``stopped short`` (the program is then partial), unless the stretch
search's judge confirms a gap there that its samples missed: then the stretch ends at the
stop and its rest is cut from the far side of the gap (:mod:`.stretch_split`). Lengths mm.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...core.errors import InputError, NothingToCutError, StartPointError
from ...core.job import Job
from ...core.progress import Progress
from ...guard import guard_for
from ...interp.cycle import BOUNDARY, COLLISION
from ...interp.stepper import Tangency
from ...program.program import STOPPED_SHORT, CutSegment, Program, Skipped
from ...program.toolpath import Toolpath, toolpath_from_record
from ..common import require_ball, run_stretch, safe_height
from ..entries import entered_program_segments
from .feasibility import FEASIBLE, Feasibility
from .pair_path import PathPlan, plan_path, shared_edge_for, stepper_for
from .stretch_paths import nearest_start, plan_for_stretch, refuse_without_stretch
from .stretch_split import split_at_stop
from .stretches import Stretch, pair_stretches

LIMIT_SLACK = 1e-3
"""mm: a cut stopping on a boundary or collision this near its stretch's end limit has
reached that limit (the finder and the stepper locate the same rule independently)."""
NO_STRETCH = "no feasible position"


def _cut_job(job: Job, st: Stretch, number: int) -> Job:
    """The job of one stretch's cut: from its start limit to its end limit."""
    op = replace(job.operation, start=tuple(st.start.p),
                 end=None if st.closed else tuple(st.end.p), edge=st.edge, stretch=number)
    return replace(job, operation=op)


def _reached_limit(tp: Toolpath, st: Stretch) -> bool:
    """Whether the cut stopped where its stretch ends (on the end, or on the rule that
    bounds the stretch there, within LIMIT_SLACK)."""
    if tp.complete:
        return True
    near = np.linalg.norm(tp.points[-1] - np.asarray(st.end.p)) <= LIMIT_SLACK
    return tp.stop_reason in (BOUNDARY, COLLISION) and bool(near)


def program_for_job(part, job: Job, *, max_cycles: int = 1_000_000,
                    progress: Progress | None = None, found=None) -> Program:
    """The :class:`Program` of a pair job on ``part`` (see the module doc).

    ``progress(cycles, 0, "<mm> mm")`` as for a path; ``found``: the pair's stretches
    when already computed (``pair_stretches``). Raises NothingToCutError (exit 3) naming
    the reason per edge when no edge has a feasible position; InputError for a ball of
    R' = 0.
    """
    op = job.operation
    i, j = op.faces
    if i is None or j is None:
        raise InputError("the job names no faces: give the two face numbers")
    require_ball(job)
    s1, s2 = part.face(i), part.face(j)
    guard = guard_for(part, (i, j), job)
    if op.start is not None:
        return _from_start(part, job, s1, s2, guard, max_cycles, progress)
    shared_edge_for(s1, s2)  # FacePairError unless they share a concave edge
    if found is None:
        found = pair_stretches(s1, s2, job, guard)
    if op.edge is not None:
        if op.edge >= len(found):
            raise InputError(f"faces {i} and {j} share {len(found)} concave edge(s): there "
                             f"is no edge {op.edge + 1}")
        found = [found[op.edge]]
    refuse_without_stretch(s1, s2, found)
    cuts, skipped = stretch_cuts(s1, s2, job, found, guard, max_cycles, progress)
    if op.stretch is not None and not cuts:
        n = max(len(e.stretches) for e in found)
        raise InputError(f"faces {i} and {j}: there is no stretch {op.stretch} (the edges "
                         f"have at most {n})")
    return entered_program(part, job, cuts, skipped)


def entered_program(part, job: Job, cuts: list[CutSegment], skipped: list[Skipped],
                    notes: list[str] | None = None) -> Program:
    """The program of a pair's ``cuts``, each entered where the tool can get to it
    (:mod:`cadcnc.ops.entries`); NothingToCutError (exit 3) naming why when none can."""
    segments, unreachable, entries = entered_program_segments(part, job, cuts,
                                                              safe_height(part, job))
    if cuts and not segments:
        i, j = job.operation.faces
        raise NothingToCutError(f"faces {i} and {j}: no cut can be reached: " + "; ".join(
            f"{s.reason}: {s.detail}" for s in unreachable))
    return Program(job, segments, skipped + unreachable, (notes or []) + entries)


def climb_measure(tp: Toolpath) -> float:
    """Mean over the path's moves of (t x z) . m: > 0 when the material lies to the right
    of the travel (climb milling with a clockwise spindle, M3), < 0 conventional, ~0 for a
    corner that runs up or down. t: unit move direction; m: the horizontal direction into
    the material, -(n1 + n2), normalised with the normals' sum (dimensionless)."""
    d = np.diff(tp.points, axis=0)
    length = np.linalg.norm(d, axis=1)
    ok = length > 0.0
    if not ok.any():
        return 0.0
    t = d[ok] / length[ok, None]
    m = -(tp.normals[1:, 0] + tp.normals[1:, 1])[ok]
    right = np.stack([t[:, 1], -t[:, 0], np.zeros(len(t))], axis=1)   # t x z
    return float(np.mean(np.einsum("ij,ij->i", right, m)))


CLIMB, CONVENTIONAL = "climb", "conventional"
SIDE_MIN = 0.05
"""|climb_measure| below this: the corner runs mostly up or down; its direction is kept."""


def _reversed(tp: Toolpath, plan: PathPlan) -> PathPlan:
    """The plan of the same cut run the other way: from its last point to its first."""
    last = Tangency(tuple(tp.points[-1]), tuple(tp.uv[-1, 0]), tuple(tp.uv[-1, 1]))
    first = plan.start
    if plan.closed:
        back = -(tp.points[1] - tp.points[0])
        return replace(plan, direction=tuple(map(float, back)))
    back = -(tp.points[-1] - tp.points[-2])
    op = replace(plan.job.operation, start=tuple(last.p), end=tuple(first.p))
    return replace(plan, job=replace(plan.job, operation=op), start=last, end=first,
                   direction=tuple(map(float, back)))


def stretch_cuts(s1, s2, job: Job, found, guard, max_cycles: int = 1_000_000,
                 steps=None, side: str | None = None, work: dict | None = None
                 ) -> tuple[list[CutSegment], list[Skipped]]:
    """A cut per stretch of ``found`` (every stretch, or stretch ``job.operation.stretch``
    of each edge), in order along each edge, and what was skipped: edges with no feasible
    position, and the rest of a stretch whose cut stopped short of its end.

    ``side``: CLIMB or CONVENTIONAL runs every cut that way (the material on the right of
    the travel for climb; see :func:`climb_measure`), re-running a cut from its other end
    where the edge's own direction is the other way; None keeps the edge's direction.
    ``work["cycles"]`` (when given) counts every stepper cycle run, re-runs included;
    ``steps``: the stepper's progress callback (``Stepper.run``: cycles, 0, the distance)."""
    i, j = s1.number, s2.number
    cuts, skipped = [], []
    work = {} if work is None else work
    work.setdefault("cycles", 0)
    for e in found:
        if not e.stretches:
            skipped.append(Skipped((i, j), NO_STRETCH, e.refusal, e.edge + 1))
            continue
        todo = [(k, st) for k, st in enumerate(e.stretches, 1)
                if job.operation.stretch is None or k == job.operation.stretch]
        while todo:
            k, st = todo.pop(0)
            cjob = _short_period(_cut_job(job, st, k), st)
            plan = replace(plan_for_stretch(s1, s2, cjob, st), job=cjob)
            if st.length <= POINT_STRETCH:
                cuts.append(CutSegment(_point_cut(plan), edge=e.edge + 1, stretch=k,
                                       at_limit=True))
                continue
            tp = run_stretch(plan, guard, max_cycles, steps)
            work["cycles"] += len(tp) - 1
            at_limit = _reached_limit(tp, st)
            split = None if at_limit else split_at_stop(e, st, tp.points[-1])
            if split is not None:   # a gap the search stepped over: the stretch ends here
                st = split[0]
                todo[:0] = [(k, rest) for rest in split[1]]
                at_limit = _reached_limit(tp, st)
            if side is not None and at_limit and len(tp) > 2:
                measure = climb_measure(tp)
                if abs(measure) >= SIDE_MIN and (measure > 0) != (side == CLIMB):
                    back = run_stretch(_reversed(tp, plan), guard, max_cycles, steps)
                    work["cycles"] += len(back) - 1
                    if _reached_limit(back, replace(st, start=st.end, end=st.start)):
                        tp = back
            cuts.append(CutSegment(tp, edge=e.edge + 1, stretch=k, at_limit=at_limit))
            if not cuts[-1].at_limit:
                skipped.append(Skipped((i, j), STOPPED_SHORT, (
                    f"stretch {k} of edge {e.edge + 1}: {tp.partial_reason}; the rest of "
                    f"the stretch ({tp.length:.3f} of {st.length:.3f} mm cut) is not cut"),
                    e.edge + 1))
    return cuts, skipped


POINT_STRETCH = 2e-3
"""mm: a stretch this short is one ball position (the ball fits a hole or a sphere of its
own radius, R' k = 1: every feasible position of the corner is the same centre), cut as a
single point reached by the plunge."""


SHORT_STEPS = 4
"""Steps at least, of a cut whose stretch is shorter than that many steps."""


def _short_period(job: Job, st: Stretch) -> Job:
    """The job of a stretch's cut, with a shorter period (the same feed) when the stretch
    is shorter than SHORT_STEPS steps: the stepper lands on its end only after 2 steps
    (so that a closed path does not stop at its start), and would otherwise run past the
    end of a stretch shorter than that (on to the next boundary)."""
    if st.closed or st.length <= POINT_STRETCH:
        return job
    chord = float(np.linalg.norm(np.subtract(st.end.p, st.start.p)))
    length = min(st.length, chord) if chord > 0.0 else st.length
    if length >= SHORT_STEPS * job.step:
        return job
    return replace(job, period=job.period * length / (SHORT_STEPS * job.step))


def _point_cut(plan: PathPlan) -> Toolpath:
    """The cut of a one-position stretch: its start point alone (no step is possible:
    the offset intersection curve is a point, the stepper's curvature rule refuses it)."""
    stepper = stepper_for(plan, 0, True, check_cycles=False)
    stepper.run(None)
    return toolpath_from_record(stepper.record, plan.job, "point", (
        "a single ball position (the ball fits the face's curvature exactly, R' k = 1): "
        "reached by the plunge"), plan.edge_length)


def _from_start(part, job, s1, s2, guard, max_cycles, progress) -> Program:
    """One cut from the user's start, moved to the nearest stretch limit when the ball
    cannot sit there (a contact off its face, a third face or the shank in the way)."""
    notes = []
    feas = Feasibility(s1, s2, job, guard)
    try:
        plan = plan_path(s1, s2, job)
        rule, detail = feas.judge(plan.start)
    except StartPointError as e:
        plan, rule, detail = None, "start", str(e)
    if rule != FEASIBLE:
        found = pair_stretches(s1, s2, job, guard)
        refuse_without_stretch(s1, s2, found)
        tan, note = nearest_start(found, feas, job.operation.start)
        notes.append(note or f"start moved into a stretch ({rule}: {detail})")
        moved = replace(job, operation=replace(job.operation, start=tuple(tan.p)))
        plan = plan_path(s1, s2, moved)
    tp = run_stretch(plan, guard, max_cycles, progress)
    cut = CutSegment(tp, edge=None, at_limit=tp.stop_reason in (BOUNDARY, COLLISION))
    return entered_program(part, plan.job, [cut], [], notes)
