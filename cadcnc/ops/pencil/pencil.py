"""Pencil milling: every inner corner of a part a ball can reach, in one linked program.

:func:`pencil` finds the corners (:func:`~cadcnc.ops.pencil.corners.find_corners`: concave shared
edges, and blends smaller than the ball, which the ball bridges on the two faces across
them), cuts every feasible stretch of each (edge corners: :mod:`.stretches` and
:func:`~cadcnc.ops.path.pair_program.stretch_cuts`; blend corners: the stepper from one seed
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

import time
from dataclasses import replace

import numpy as np

from ...errors import CadcncError
from ...geometry.part import Part
from ...job import DEFAULT_FEED, DEFAULT_PERIOD, Job, PairPath, Pencil, Tool
from ...program.linking import linked, order_cuts
from ...program.program import CutSegment, Program, Skipped
from ...tolerances import DEFAULT, Tolerances
from .corners import BLEND, EDGE, find_corners
from ...guard import guard_for
from ..common import run_stretch, safe_height
from ..path.pair_program import CLIMB, stretch_cuts
from ..path.pair_path import plan_path
from ..path.stretches import Feasibility, edge_stretches, pair_stretches

CHAIN_GAP = 1e-3
"""mm: a cut starting this near another's end continues it (no lift)."""


def pencil(part, *, radius: float, allowance: float = 0.0, feed: float = DEFAULT_FEED,
           period: float = DEFAULT_PERIOD, faces=None, clearance: float | None = None,
           shank_length: float | None = None, side: str = CLIMB,
           tol: Tolerances = DEFAULT, progress=None, times: dict | None = None) -> Program:
    """The pencil program of ``part`` (a :class:`~cadcnc.geometry.part.Part`, or a CadQuery
    Workplane or Shape, read with :meth:`Part.from_cadquery`) for a ball of radius
    ``radius`` (mm) with ``allowance`` (mm): see the module doc. A keyword convenience
    that builds the :class:`~cadcnc.job.Job` of :func:`pencil_program`.

    ``faces``: face numbers to restrict the corners to (both faces of a corner must be
    among them); ``clearance``: ball-centre Z of the links (default the part's top + 10
    mm); ``side``: "climb" (default: the material on the right of the travel, for a
    clockwise spindle) or "conventional"; ``progress``, ``times``: see
    :func:`pencil_program`.
    """
    if not isinstance(part, Part):
        part = Part.from_cadquery(part, tol)
    job = Job(Tool(radius, allowance, shank_length), feed, period,
              Pencil(None if faces is None else tuple(sorted(faces)), side),
              source=part.source, clearance=clearance, tolerances=tol)
    return pencil_program(part, job, progress=progress, times=times)


def pencil_program(part: Part, job: Job, *, progress=None, times: dict | None = None
                   ) -> Program:
    """The pencil program of a :class:`~cadcnc.job.Pencil` ``job`` on ``part``.

    ``progress(done, total, what)`` after each corner. ``times``: a dict to which the
    seconds spent per stage are added (``edges``: the part's edge classification;
    ``corners``; ``guards``: building the third-face guards; ``stretches``: the stretch
    search; ``interpolation``: the stepper along every stretch; ``linking``: reachability
    from +Z, ordering and links).
    """
    clock = _Clock(times)
    op, tool = job.operation, job.tool
    side = op.side
    faces = None if op.faces is None else set(op.faces)
    radius, allowance = tool.radius, tool.allowance
    with clock("edges"):
        part.adjacency
    with clock("corners"):
        corners = find_corners(part, radius, allowance, faces)
    cuts: list[CutSegment] = []
    skipped: list[Skipped] = [c.skipped() for c in corners if not c.cut]
    todo = [c for c in corners if c.cut]
    stretches: dict = {}
    guards: dict = {}
    for k, corner in enumerate(todo, 1):
        i, j = corner.faces
        cjob = replace(job, operation=PairPath(faces=(i, j), edge=corner.edge))
        try:
            s1, s2 = part.face(i), part.face(j)
            with clock("guards"):   # one per pair (its cache serves all its corners)
                guard = guards.get((i, j)) or guards.setdefault(
                    (i, j), guard_for(part, (i, j), cjob))
            if corner.kind == EDGE:
                with clock("stretches"):
                    if (i, j) not in stretches:
                        stretches[(i, j)] = pair_stretches(s1, s2, cjob, guard)
                found = [stretches[(i, j)][corner.edge]]
                with clock("interpolation"):
                    new, why = stretch_cuts(s1, s2, cjob, found, guard, side=side)
                cuts += new
                skipped += why
            elif corner.kind == BLEND and len(corner.rails) == 1:
                # the ball's stretches anchored on planes normal to the blend's rail on a
                with clock("stretches"):
                    found = [edge_stretches(Feasibility(s1, s2, cjob, guard),
                                            corner.rails[0], 0)]
                with clock("interpolation"):
                    new, why = stretch_cuts(s1, s2, cjob, found, guard, side=side)
                cuts += new
                skipped += [replace(w, detail=f"blend corner over face(s) "
                                    f"{', '.join(map(str, corner.blend_faces))}: {w.detail}")
                            for w in why]
            elif corner.kind == BLEND:
                with clock("interpolation"):
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
    with clock("linking"):
        z_safe = safe_height(part, job)
        ordered, unreachable = reachable_order(part, job, cuts, z_safe)
        segments = linked(ordered, z_safe, join=CHAIN_GAP)
    return Program(job, segments, skipped + unreachable)


class _Clock:
    """``with clock(stage):`` adds the block's wall seconds to ``times[stage]`` (no-op
    without a dict)."""

    def __init__(self, times: dict | None):
        self.times = times
        self.stage = ""
        self.t0 = 0.0

    def __call__(self, stage: str) -> "_Clock":
        self.stage = stage
        return self

    def __enter__(self) -> None:
        self.t0 = time.perf_counter()

    def __exit__(self, *exc) -> None:
        if self.times is not None:
            self.times[self.stage] = self.times.get(self.stage, 0.0) + (
                time.perf_counter() - self.t0)


NOT_REACHABLE = "not reachable from +Z"


def reachable_order(part: Part, job: Job, cuts: list[CutSegment], z_safe: float
                    ) -> tuple[list[CutSegment], list[Skipped]]:
    """The cuts the tool can reach from above, in linking order (:func:`order_cuts`), and
    the others skipped as "not reachable from +Z". A chain is entered by a plunge straight
    down to its first cut's start and left by a retract straight up from its last cut's
    end (:func:`~cadcnc.program.linking.link`). Such a point is reachable when the ball
    and a shank from it up to the link height ``z_safe`` (mm) clear the part by R' - 1 um
    less the gate's tolerance (:func:`.guard.guard_for`, the stepper's guard with a longer
    shank): not so in a sealed
    void, or under an overhang higher than the shank. A cut whose entry or exit is
    blocked is dropped and the rest ordered again (its neighbours may then need one)."""
    lo, _ = part.bounding_box()
    shank = max(z_safe - float(lo[2]), job.tool.shank)
    guards: dict = {}
    skipped: list[Skipped] = []

    def blocked(cut: CutSegment, which: str, p) -> str | None:
        faces = cut.path.faces
        if faces not in guards:
            guards[faces] = guard_for(part, faces, job, shank=shank)
        margin, detail = guards[faces].margin(p)
        # a cut's end landed on a collision sits at margin ~0 (-1e-8 mm is landing
        # round-off): only a deeper hit blocks the way; the gate judges every move anyway
        return None if margin >= -job.tolerances.gouge else (
            f"its {which} ({p[0]:.4f}, {p[1]:.4f}, {p[2]:.4f}): {detail} "
            f"({-margin:.4g} mm too near) on the way to Z {z_safe:.3f}")

    while True:
        ordered = order_cuts(cuts, CHAIN_GAP)
        bad = {}
        for k, cut in enumerate(ordered):
            why = []
            if k == 0 or np.linalg.norm(cut.points[0] - ordered[k - 1].points[-1]) > CHAIN_GAP:
                why.append(blocked(cut, "start", cut.points[0]))
            if k == len(ordered) - 1 or np.linalg.norm(
                    ordered[k + 1].points[0] - cut.points[-1]) > CHAIN_GAP:
                why.append(blocked(cut, "end", cut.points[-1]))
            why = [w for w in why if w]
            if why:
                bad[id(cut)] = why
        if not bad:
            return ordered, skipped
        for cut in ordered:
            if id(cut) in bad:
                skipped.append(Skipped(cut.path.faces, NOT_REACHABLE, (
                    f"cut of {cut.path.length:.3f} mm: " + "; ".join(bad[id(cut)])),
                    cut.edge))
        cuts = [c for c in ordered if id(c) not in bad]


def _blend_cut(s1, s2, job: Job, corner, guard) -> CutSegment:
    """The cut bridging a blend: from its first seed to its second (once around when the
    blend is closed), stopped by the guard or a boundary where the ball cannot go on."""
    seeds = corner.seeds
    op = replace(job.operation, start=tuple(seeds[0]),
                 end=tuple(seeds[1]) if len(seeds) > 1 else None, edge=None)
    plan = plan_path(s1, s2, replace(job, operation=op))
    tp = run_stretch(plan, guard, 1_000_000, None, allow_empty=True)
    return CutSegment(tp, edge=None, at_limit=tp.stop_reason in ("boundary", "collision"))
