"""Pencil milling: every inner corner of a part a ball can reach, in one linked program.

:func:`pencil_program` finds the corners (:func:`~cadcnc.ops.pencil.corners.find_corners`:
concave shared edges, and blends smaller than the ball, which the ball bridges on the two
faces across them), cuts every feasible stretch of each (edge corners: :mod:`.stretches` and
:func:`~cadcnc.ops.path.pair_program.stretch_cuts`; blend corners: the stepper from one seed
to the other), with the third-face and shank guard inside the stepper, then orders the
cuts (chains first, where one stops tri-tangent or on a boundary exactly where the next
starts; nearest neighbour; 2-opt) and links them (retract, rapid, plunge; a chain's cuts
follow each other by one short feed move), each cut entered where the tool can get to it
(:mod:`cadcnc.ops.entries`: its start, its end, a point between, or from the side).
Corners that cannot be cut are listed in the program's ``skipped`` with the reason. Lengths mm, feed mm/min, period s.

Direction: ``side="climb"`` (default) runs every corner with the material on the right
of the travel (climb milling with a clockwise spindle), ``"conventional"`` the other
way; a cut whose corner runs the other way is interpolated again from its other limit
(not the same points backwards). Corners running mostly up or down keep their direction,
and so do blend corners (from the blend's first seed to its second).
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

from ...core.errors import CadcncError
from ...core.job import Job, PairPath
from ...core.progress import Progress
from ...core.tolerances import DEFAULT
from ...core.work_limits import MAX_CYCLES, Heartbeat, refuse_over
from ...geometry.part import Part
from ...guard import guard_for
from ...parallel.tasks import on_workers
from ...program.linking import order_cuts
from ...program.program import CutSegment, Program, Skipped
from ..common import CHAIN_GAP, refuse_cycles, require_ball, run_stretch, safe_height
from ..entries import UNREACHABLE, entered_program_segments
from ..path.feasibility import Feasibility
from ..path.limit_search import limit_samples
from ..path.pair_path import plan_path
from ..path.pair_program import stretch_cuts
from ..path.stretches import MIN_SAMPLES, SPACING, edge_stretches, pair_stretches
from .corners import BLEND, EDGE, Corner, find_corners


def pencil_program(part: Part, job: Job, *, progress: Progress | None = None,
                   times: dict | None = None,
                   max_cycles: int = MAX_CYCLES, clock=time.monotonic,
                   work: dict | None = None, processes: int | None = 1) -> Program:
    """The pencil program of a :class:`~cadcnc.core.job.Pencil` ``job`` on ``part``.

    ``progress(done, total, what)`` after each corner, and within a corner at least every
    HEARTBEAT_S seconds of ``clock`` (the stretch search, sample by sample; the stepper;
    the linking), ``done`` then counting the corners finished. ``times``: a dict to which
    the seconds spent per stage are added (``edges``: the part's edge classification;
    ``corners``; ``guards``: building the third-face guards; ``stretches``: the stretch
    search; ``interpolation``: the stepper along every stretch; ``linking``: reachability
    from +Z, ordering and links). Before any corner is cut, the work is estimated
    (:func:`estimate_work`) and refused over ``max_cycles`` interpolation cycles or
    MAX_SAMPLES search samples (:class:`~cadcnc.core.work_limits.WorkLimitError`, exit 2); ``work``:
    a dict given the estimates and the counts (``cycles_estimate``, ``samples_estimate``,
    ``cycles``: every stepper cycle run, re-runs included; ``samples``). ``processes``:
    processes cutting the corners, one pair's corners a task (None: every core); the
    program does not depend on it; ``times`` then adds the workers' seconds.
    """
    require_ball(job)
    stage = _Clock(times)
    op, tool = job.operation, job.tool
    faces = None if op.faces is None else set(op.faces)
    radius, allowance = tool.radius, tool.allowance
    with stage("edges"):
        part.adjacency
    with stage("corners"):
        corners = find_corners(part, radius, allowance, faces, job.tolerances)
    cuts: list[CutSegment] = []
    skipped: list[Skipped] = [c.skipped() for c in corners if not c.cut]
    todo = [c for c in corners if c.cut]
    work = {} if work is None else work
    work.update(estimate_work(todo, job, max_cycles), cycles=0, samples=0)
    beat = Heartbeat(progress and (lambda text: progress(done, len(todo), text)), clock=clock)
    done = 0
    groups: dict = {}   # corners of one pair share its guard and stretch search: one task
    for k, corner in enumerate(todo):
        groups.setdefault(corner.faces, []).append(k)
    per_corner: list = [None] * len(todo)

    def arrived(_: int, res) -> None:
        nonlocal done
        for k, cut_skip in res[0]:
            per_corner[k] = cut_skip
            done += 1
            if progress is not None:
                progress(done, len(todo), "faces {} {}".format(*todo[k].faces))
                beat.last = beat.clock()

    portable = (lambda c: c) if processes == 1 else (lambda c: rail_refs(part, c))
    tasks = [(job, [(k, portable(todo[k])) for k in ks], max_cycles)
             for ks in groups.values()]
    sizes = [sum(todo[k].length + search_samples(todo[k].length, tool.offset, todo[k].closed)
                 for k in ks) for ks in groups.values()]   # the largest pairs first
    for _, seconds, counts in on_workers(_pair_corners, tasks, part, processes, arrived,
                                         "the corners of pair", beat, sizes):
        for name, t in seconds.items():
            stage.add(name, t)
        for name, n in counts.items():
            work[name] += n
    for new, why in per_corner:
        cuts += new
        skipped += why
    with stage("linking"):   # entries (ops/entries.py), ordering and links
        segments, unreachable, notes = entered_program_segments(
            part, job, cuts, safe_height(part, job), join=CHAIN_GAP,
            order=lambda items: order_cuts(items, CHAIN_GAP),
            tick=lambda k, n: beat.beat(f"linking: {k} of {n} cuts entered"), processes=processes)
    return Program(job, segments, skipped + unreachable, notes)


def _pair_corners(part: Part, task, beat=None) -> tuple[list, dict, dict]:
    """The cuts and skips of the corners of one pair (they share its guard and stretch
    search): ``([(corner index, (cuts, skipped))], seconds per stage, work counts)``;
    :func:`~cadcnc.parallel.tasks.on_workers`' task."""
    job, corners, max_cycles = task
    times: dict = {}
    stage = _Clock(times)
    work = {"cycles": 0, "samples": 0}
    side = job.operation.side
    beat = beat if beat is not None else Heartbeat(None)
    guard, found_pair, out = None, None, []
    for k, corner in corners:
        corner = rails_back(part, corner)
        i, j = corner.faces
        cjob = replace(job, operation=PairPath(faces=(i, j), edge=corner.edge))
        at = f"faces {i} {j}"
        feas = None
        steps = (lambda cycles, _total, _travelled: beat.beat(
            f"{at}: interpolating, {cycles} cycles"))
        cuts: list[CutSegment] = []
        skipped: list[Skipped] = []
        try:
            s1, s2 = part.face(i), part.face(j)
            with stage("guards"):   # one per pair (its cache serves all its corners)
                guard = guard or guard_for(part, (i, j), cjob)
            beat.beat(f"{at}: guard built")
            feas = Feasibility(s1, s2, cjob, guard)
            feas.beat = lambda: beat.beat(lambda: f"{at}: stretch search, {feas.samples} "
                                          "ball positions")
            if corner.kind == EDGE:
                with stage("stretches"):
                    if found_pair is None:
                        found_pair = pair_stretches(s1, s2, cjob, guard, feas=feas)
                found = [found_pair[corner.edge]]
                with stage("interpolation"):
                    new, why = stretch_cuts(s1, s2, cjob, found, guard, max_cycles, steps,
                                            side=side, work=work)
                cuts += new
                skipped += why
            elif corner.kind == BLEND and len(corner.rails) == 1:
                # the ball's stretches anchored on planes normal to the blend's rail on a
                with stage("stretches"):
                    found = [edge_stretches(feas, corner.rails[0], 0)]
                with stage("interpolation"):
                    new, why = stretch_cuts(s1, s2, cjob, found, guard, max_cycles, steps,
                                            side=side, work=work)
                cuts += new
                skipped += [replace(w, detail=f"blend corner over face(s) "
                                    f"{', '.join(map(str, corner.blend_faces))}: {w.detail}")
                            for w in why]
            elif corner.kind == BLEND:
                with stage("interpolation"):
                    cut = blend_cut(s1, s2, cjob, corner, guard, max_cycles, steps)
                work["cycles"] += len(cut.points) - 1
                if len(cut.points) < 2:
                    skipped.append(Skipped((i, j), cut.path.stop_reason, (
                        f"blend corner over face(s) {', '.join(map(str, corner.blend_faces))}"
                        f": no step from its first seed: {cut.path.stop_detail}")))
                else:
                    cuts.append(cut)
        except CadcncError as e:
            skipped.append(Skipped((i, j), "failed", f"{corner.kind} corner: {e}",
                                   None if corner.edge is None else corner.edge + 1))
        work["samples"] += 0 if feas is None else feas.samples
        out.append((k, (cuts, skipped)))
    return out, times, work


def rail_refs(part: Part, corner: Corner) -> Corner:
    """``corner`` with its rails (OCCT edges, which do not pickle) as (faces, index) in
    the part's adjacency, for a worker to find again (:func:`rails_back`)."""
    refs = []
    for rail in corner.rails:
        edges = part.shared_edges(*rail.faces)
        refs.append((rail.faces, next(k for k, e in enumerate(edges) if e is rail)))
    return replace(corner, rails=tuple(refs))


def rails_back(part: Part, corner: Corner) -> Corner:
    """``corner`` with rails given by :func:`rail_refs` found again in ``part``."""
    if not corner.rails or not isinstance(corner.rails[0], tuple):
        return corner
    return replace(corner, rails=tuple(part.shared_edges(*faces)[k]
                                       for faces, k in corner.rails))


MAX_SAMPLES = 400_000
"""Ball positions one stretch search may solve in all (about a minute or two): over it,
the search is refused up front (:func:`search_samples`)."""


def search_samples(length: float, offset: float, closed: bool = False,
                   tol: float = DEFAULT.stretch_limit) -> int:
    """About how many ball positions the search of an edge of ``length`` mm solves for a
    ball of offset R' = ``offset`` mm: the grid every SPACING mm (at least MIN_SAMPLES),
    R' + 1 mm past each end of an open edge, and the search of two limits (SPACING to
    ``tol``, the job's ``stretch_limit``: a bisection's count, which a limit with a margin
    undercuts); more stretches and the refinement add on top."""
    n = max(MIN_SAMPLES, int(math.ceil(length / SPACING)) + 1)
    ext = 0.0 if closed else max(offset, 0.0) + 1.0
    bisect = 2 * limit_samples(SPACING, tol)
    return n + 2 * int(math.ceil(ext / max(SPACING, length / max(n - 1, 1)))) + bisect


def estimate_work(todo: list[Corner], job: Job, max_cycles: int = MAX_CYCLES) -> dict:
    """The work of cutting the corners ``todo``, estimated before any is searched or cut,
    and refused (:class:`~cadcnc.core.work_limits.WorkLimitError`) over its limit:
    ``cycles_estimate``: their lengths over the step F Ts, twice (a cut whose corner runs
    against ``side`` is run again from its other end), over ``max_cycles``; ``samples_estimate``: the ball positions their stretch search solves
    (:func:`search_samples`), over MAX_SAMPLES."""
    rp = job.tool.offset
    length = sum(c.length for c in todo)
    samples = sum(search_samples(c.length, rp, c.closed, job.tolerances.stretch_limit)
                  for c in todo
                  if c.kind == EDGE or len(c.rails) == 1)
    runs = 1 if job.operation.side is None else 2   # a cut may be run again the other way
    cycles = refuse_cycles([runs * length], job, f"pencil of {len(todo)} corner(s)",
                           max_cycles)
    refuse_over(f"the stretch search of {len(todo)} corner(s) ({length:.4g} mm of corners, "
                f"searched R' + 1 = {rp + 1:.4g} mm past each end)", samples, MAX_SAMPLES,
                "ball positions", "a smaller --radius or --allowance, or fewer corners "
                "(--faces)")
    return dict(cycles_estimate=cycles, samples_estimate=samples)


class _Clock:
    """``with stage(name):`` adds the block's wall seconds to ``times[stage]`` (no-op
    without a dict)."""

    def __init__(self, times: dict | None):
        self.times = times
        self.stage = ""
        self.t0 = 0.0

    def add(self, stage: str, seconds: float) -> None:
        """Add ``seconds`` measured elsewhere (a worker) to ``stage``."""
        if self.times is not None:
            self.times[stage] = self.times.get(stage, 0.0) + seconds

    def __call__(self, stage: str) -> "_Clock":
        self.stage = stage
        return self

    def __enter__(self) -> None:
        self.t0 = time.perf_counter()

    def __exit__(self, *exc) -> None:
        if self.times is not None:
            self.times[self.stage] = self.times.get(self.stage, 0.0) + (
                time.perf_counter() - self.t0)


NOT_REACHABLE = UNREACHABLE
"""The reason of a cut no entry reaches (:mod:`cadcnc.ops.entries`)."""


def blend_cut(s1, s2, job: Job, corner, guard, max_cycles: int, progress) -> CutSegment:
    """The cut bridging a blend: from its first seed to its second (once around when the
    blend is closed), stopped by the guard or a boundary where the ball cannot go on."""
    seeds = corner.seeds
    op = replace(job.operation, start=tuple(seeds[0]),
                 end=tuple(seeds[1]) if len(seeds) > 1 else None, edge=None)
    plan = plan_path(s1, s2, replace(job, operation=op))
    tp = run_stretch(plan, guard, max_cycles, progress, allow_empty=True)
    return CutSegment(tp, edge=None, at_limit=tp.stop_reason in ("boundary", "collision"))
