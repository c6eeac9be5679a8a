"""Pencil milling: every inner corner of a part a ball can reach, in one linked program.

:func:`pencil` finds the corners (:func:`~cadcnc.ops.corners.find_corners`: concave shared
edges, and blends smaller than the ball, which the ball bridges on the two faces across
them), cuts every feasible stretch of each (edge corners: :mod:`.stretches` and
:func:`~cadcnc.ops.pair_program.stretch_cuts`; blend corners: the stepper from one seed
to the other), with the third-face and shank guard inside the stepper, then orders the
cuts (chains first, where one stops tri-tangent or on a boundary exactly where the next
starts; nearest neighbour; 2-opt) and links them (retract, rapid, plunge; a chain's cuts
follow each other by one short feed move). Corners that cannot be cut are listed in the
program's ``skipped`` with the reason. Lengths mm, feed mm/min, period s.

Direction: ``side="climb"`` (default) runs every corner with the material on the right
of the travel (climb milling with a clockwise spindle), ``"conventional"`` the other
way; a cut whose corner runs the other way is interpolated again from its other limit
(not the same points backwards). Corners running mostly up or down keep their direction,
and so do blend corners (from the blend's first seed to its second) in this version.
"""

from __future__ import annotations

from dataclasses import replace

from ..errors import CadcncError, InputError
from ..geometry.clearance import guard_for
from ..job import Job, PairPath, Tool
from ..program.linking import linked, order_cuts
from ..program.program import CutSegment, Program, Skipped
from ..tolerances import DEFAULT, Tolerances
from .corners import BLEND, EDGE, find_corners
from .pair_program import CLIMB, CONVENTIONAL, _run, safe_height, stretch_cuts
from .pair_path import plan_path
from .stretches import pair_stretches

CHAIN_GAP = 1e-3
"""mm: a cut starting this near another's end continues it (no lift)."""
DEFAULT_FEED = 1500.0     # mm/min: with DEFAULT_PERIOD, the paper's 0.1 mm step
DEFAULT_PERIOD = 0.004    # s


def pencil(part, *, radius: float, allowance: float = 0.0, feed: float = DEFAULT_FEED,
           period: float = DEFAULT_PERIOD, faces=None, clearance: float | None = None,
           shank_length: float | None = None, side: str = CLIMB,
           tol: Tolerances = DEFAULT, progress=None) -> Program:
    """The pencil program of ``part`` (a :class:`~cadcnc.geometry.part.Part`) for a ball of
    radius ``radius`` (mm) with ``allowance`` (mm): see the module doc.

    ``faces``: face numbers to restrict the corners to (both faces of a corner must be
    among them); ``clearance``: ball-centre Z of the links (default the part's top + 10
    mm); ``side``: "climb" (default: the material on the right of the travel, for a
    clockwise spindle) or "conventional"; ``progress(done, total, what)`` after each corner.
    """
    if side not in (CLIMB, CONVENTIONAL):
        raise InputError(f"side must be {CLIMB!r} or {CONVENTIONAL!r}, got {side!r}")
    tool = Tool(radius, allowance, shank_length)
    job = Job(tool, feed, period, PairPath(edge=None), source=part.source,
              clearance=clearance, tolerances=tol)
    corners = find_corners(part, radius, allowance, faces)
    cuts: list[CutSegment] = []
    skipped: list[Skipped] = [c.skipped() for c in corners if not c.cut]
    todo = [c for c in corners if c.cut]
    stretches: dict = {}
    for k, corner in enumerate(todo, 1):
        i, j = corner.faces
        cjob = replace(job, operation=PairPath(faces=(i, j), edge=corner.edge))
        try:
            s1, s2 = part.face(i), part.face(j)
            guard = guard_for(part, (i, j), cjob)
            if corner.kind == EDGE:
                if (i, j) not in stretches:
                    stretches[(i, j)] = pair_stretches(s1, s2, cjob, guard)
                found = [stretches[(i, j)][corner.edge]]
                new, why = stretch_cuts(s1, s2, cjob, found, guard, side=side)
                cuts += new
                skipped += why
            elif corner.kind == BLEND:
                cut = _blend_cut(s1, s2, cjob, corner, guard)
                if len(cut.points) < 2:
                    skipped.append(Skipped((i, j), cut.path.stop_reason, (
                        f"blend corner over face(s) {', '.join(map(str, corner.blend_faces))}"
                        f": no step from its first seed: {cut.path.stop_detail}")))
                else:
                    cuts.append(cut)
        except CadcncError as e:
            skipped.append(Skipped((i, j), "failed", f"{corner.kind} corner: {e}",
                                   None if corner.edge is None else corner.edge + 1))
        if progress is not None:
            progress(k, len(todo), f"faces {i} {j}")
    ordered = order_cuts(cuts, CHAIN_GAP)
    return Program(job, linked(ordered, safe_height(part, job), join=CHAIN_GAP), skipped)


def _blend_cut(s1, s2, job: Job, corner, guard) -> CutSegment:
    """The cut bridging a blend: from its first seed to its second (once around when the
    blend is closed), stopped by the guard or a boundary where the ball cannot go on."""
    seeds = corner.seeds
    op = replace(job.operation, start=tuple(seeds[0]),
                 end=tuple(seeds[1]) if len(seeds) > 1 else None, edge=None)
    plan = plan_path(s1, s2, replace(job, operation=op))
    tp = _run(plan, guard, 1_000_000, None, allow_empty=True)
    return CutSegment(tp, edge=None, at_limit=tp.stop_reason in ("boundary", "collision"))
