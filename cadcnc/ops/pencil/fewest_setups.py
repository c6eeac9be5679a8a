"""The fewest setups: the pencil program of a part from several tool axes (issue 23).

Each candidate axis (the six principal ones, or those given) is judged in its own setup
(:mod:`cadcnc.geometry.setup`) from samples (:mod:`.reach_samples`); only the chosen ones
get their pencil program (:func:`choose`). What a setup reaches is counted in *positions*:
the part's concave shared edges (of the selected faces) sampled every SPACING mm along
their length; a cut point (ball centre, part coordinates) reaches the sample of its corner
nearest to it (within REACH_RADII R'). A blend corner (two faces sharing no edge) counts
its ball centres on a VOXEL mm grid instead. The setups chosen are the fewest whose union
reaches every position any candidate reaches: checked over every subset of the
candidates (2^6 = 64 at most), so the count is optimal; among the smallest covering
subsets the one reaching the most positions in total wins, machined in decreasing reach
(+Z first on ties). A later setup does not cut what an earlier one cut: its cuts are
trimmed to the positions still to cut, plus ``overlap`` mm of arc length either side
(a lap at the boundary), then ordered and linked again. Positions no candidate reaches
are listed per corner with each axis's reason. Lengths mm.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ...core.errors import CadcncError, InputError, NothingToCutError
from ...core.job import PRINCIPAL_AXES, Job, Pencil, axis_name
from ...core.units import check_axis
from ...geometry.part import Part
from ...geometry.setup import Setup, original_part, setup_in, setup_part
from ...program.linking import order_cuts
from ...program.program import CutSegment, Program, Skipped
from ...program.transform import in_part_coordinates
from ..common import CHAIN_GAP, safe_height
from ..entries import entered_program_segments
from ..path.pair_program import NO_STRETCH
from ..run import RunOptions, operation_of
from .reach_samples import BallSamples, axis_reach, ball_samples, stretch_lines, true_runs
from .setup_positions import SPACING, corner_positions, cut_keys, edge_positions, line_keys

AUTO = "auto"
AUTO_ORDER = ("+Z", "-Z", "+X", "-X", "+Y", "-Y")  # the candidates of AUTO, +Z first on ties
TRIMMED = "setup boundary"  # the stop reason of a cut trimmed where an earlier setup cut


@dataclass
class SetupRun:
    """One candidate setup: its part turned into the setup, the positions its samples
    reach (``sampled``, :mod:`.reach_samples`) and, once its program is ``computed`` (work
    coordinates), the positions the program reaches (``reached``; the samples' until then)
    and cuts (``assigned``: not cut by an earlier setup)."""

    setup: Setup
    part: Part
    program: Program
    reached: int
    assigned: int = 0
    error: str = ""   # why it reaches nothing (its operation refused the part), or ""
    sampled: int = 0
    computed: bool = False
    keys: list = field(default_factory=list, repr=False)   # per cut, per point: position


@dataclass
class SetupsResult:
    """The setups chosen, in machining order (``runs``), every candidate's reach by name
    (from its samples), the positions reachable (``positions``), those no candidate
    reaches (``unreached``: (faces, count, reasons per axis)), the subsets checked for the
    fewest, and every candidate (``candidates``; the chosen ones computed)."""

    runs: list[SetupRun]
    reach: dict[str, int]
    positions: int
    unreached: list[tuple[tuple[int, int], int, str]] = field(default_factory=list)
    subsets_checked: int = 0
    candidates: list[SetupRun] = field(default_factory=list)

    def summary_lines(self) -> list[str]:
        """Sentences for the user: the setups, their cuts and shares, what no axis reaches."""
        n = max(self.positions, 1)
        computed = " ".join(r.setup.name for r in self.candidates if r.computed) or "none"
        out = [f"setups     {len(self.runs)} of {len(self.reach)} candidate axes reach all "
               f"{self.positions} reachable corner positions ({SPACING:g} mm apart); fewest "
               f"(optimal: every one of {self.subsets_checked} subsets checked)",
               "reach      " + ", ".join(f"{k} {v}" for k, v in self.reach.items())
               + f" (from samples; programs computed: {computed})"]
        for r in self.runs:
            out.append(f"setup {r.setup.name:<4} {len(r.program.cuts)} cuts, "
                       f"{r.program.cut_length:.1f} mm, {r.assigned} positions "
                       f"({100.0 * r.assigned / n:.1f} %), reaches {r.reached}")
        for faces, count, why in self.unreached:
            where = "" if faces == (0, 0) else f"faces {faces[0]} {faces[1]}: "
            out.append(f"unreached  {where}{count} positions: {why}")
        return out


def parse_setups(value) -> list[tuple[float, float, float]] | str:
    """AUTO, or the axes of "+Z,-X,..." / a sequence of axes (InputError naming the bad one)."""
    if isinstance(value, str) and value.strip().lower() == AUTO:
        return AUTO
    items = value.split(",") if isinstance(value, str) else list(value)
    axes = []
    for item in items:
        if isinstance(item, str) and item.strip().upper().lstrip("+-") not in ("X", "Y", "Z"):
            raise InputError(f"setups: {item!r} is not an axis name (+Z, -Z, +X, -X, +Y, -Y)"
                             " nor auto")
        axes.append(check_axis(item))
    if not axes:
        raise InputError("setups: give auto or at least one axis")
    return list(dict.fromkeys(axes))


def pencil_setups(part: Part, job: Job, setups="auto", overlap: float = 0.0, *,
                  progress=None, max_cycles: int | None = None,
                  processes: int | None = 1) -> SetupsResult:
    """The fewest setups of ``job`` (a :class:`~cadcnc.core.job.Pencil` job) on ``part`` among
    ``setups`` (AUTO: the six principal axes; or a list of axes): module doc. ``overlap``:
    mm of lap at a boundary with an earlier setup; ``processes``: processes for each setup's
    corners (None: every core). Raises NothingToCutError when no candidate reaches
    anything."""
    if not isinstance(job.operation, Pencil):
        raise InputError("setups are for the pencil operation")
    if not (isinstance(overlap, (int, float)) and overlap >= 0 and np.isfinite(overlap)):
        raise InputError(f"setup overlap must be a length >= 0 mm, got {overlap!r}")
    axes = [PRINCIPAL_AXES[n] for n in AUTO_ORDER] if parse_setups(setups) == AUTO else \
        parse_setups(setups)
    part = original_part(part)
    samples = corner_positions(part, job)
    extra = {} if max_cycles is None else {"max_cycles": max_cycles}
    options = RunOptions(progress=progress, processes=processes, **extra)
    counts = {pair: {k: len(pts) for k, pts in edges}
              for pair, edges in edge_positions(part, job).items()}
    balls = ball_samples(part, job, counts, SPACING, processes=processes)
    runs, reach_sets = [], []
    for n, axis in enumerate(axes):
        run, keys = _sampled(part, job, axis, samples, balls, options)
        runs.append(run)
        reach_sets.append(keys)
        if progress is not None:
            progress(n + 1, len(axes), f"reach samples of setup {run.setup.name}")
    chosen, checked, universe = _chosen(runs, reach_sets, samples, job, options)
    result = SetupsResult([], {r.setup.name: r.sampled for r in runs}, len(universe),
                          _unreached(samples, universe, runs), checked, runs)
    if not universe:
        why = "; ".join(f"{r.setup.name}: {r.error or 'no cut'}" for r in runs)
        raise NothingToCutError(f"no setup reaches any corner position ({why})")
    taken: set = set()
    for k in chosen:
        run = runs[k]
        run.assigned = len(reach_sets[k] - taken)
        if taken:
            run.program = _trimmed(run, run.keys, taken, overlap)
        taken |= reach_sets[k]
        result.runs.append(run)
    return result


def _chosen(runs: list[SetupRun], reach: list[set], samples: dict, job: Job,
            options: RunOptions) -> tuple[list[int], int, set]:
    """:func:`choose` on the candidates ``runs``, their samples' ``reach`` (updated), a
    program computed with :func:`_computed`, a closer look with the stretch search."""
    def look(k: int, pair: tuple[int, int]) -> set:
        keys = line_keys({pair: stretch_lines(runs[k].part, runs[k].program.job, pair,
                                               max_cycles=options.max_cycles)}, samples, job)
        runs[k].reached = len({key for key in reach[k] if key[0] != pair} | keys)
        return keys

    return choose(reach, lambda k: _computed(runs[k], samples, job, options), look)


def choose(reach: list[set], compute: Callable[[int], set],
           look: Callable[[int, tuple], set]) -> tuple[list[int], int, set]:
    """The fewest setups (:func:`_fewest`) chosen from estimates of each candidate's
    reach (``reach``: sets of position keys, (pair, index); updated in place), each
    chosen one then computed (``compute(k)``: the positions its program reaches) until
    the chosen are all computed. Once some are, a candidate chosen for positions no
    computed program reaches first has its estimate of those pairs replaced by
    ``look(k, pair)`` (a closer look; ``compute`` only if it still is chosen).

    Where every estimate holds every position its program reaches (the samples' do but
    for the cases :mod:`.reach_samples` names), the choice is the one all the programs
    give: the chosen cover those programs' union with their own, a smaller or
    higher-scoring subset would cover it with the estimates, and ties fall alike.
    Returns (chosen, subsets checked, universe)."""
    computed: set = set()
    looked: set = set()   # (candidate, pair) looked at closer
    while True:
        universe = set().union(*reach)
        chosen, checked = _fewest(reach, universe)
        todo = [k for k in chosen if k not in computed]
        if not todo:
            return chosen, checked, universe
        if computed:
            cut = set().union(*(reach[k] for k in computed))
            pairs = {(k, key[0]) for k in todo for key in reach[k] - cut} - looked
            if pairs:
                for k, pair in sorted(pairs):
                    reach[k] = {key for key in reach[k] if key[0] != pair} | look(k, pair)
                looked |= pairs
                continue
        for k in todo:
            reach[k] = compute(k)
            computed.add(k)


def _sub_job(job: Job, axis) -> Job:
    """``job`` along ``axis`` (its origin kept for its own axis only)."""
    return replace(job, axis=axis, origin=None if axis != job.axis else job.origin)


def _sampled(part: Part, job: Job, axis, samples: dict, balls: BallSamples,
             options: RunOptions) -> tuple[SetupRun, set]:
    """The candidate of ``axis`` (not computed) and the positions its samples reach
    (:mod:`.reach_samples`; ``balls``: the axis-free samples)."""
    sub = _sub_job(job, axis)
    sp = setup_part(part, sub)
    setup = setup_in(sp) or Setup(np.asarray(axis), np.eye(3), np.zeros(3))
    try:
        lines = axis_reach(sp, sub, balls, max_cycles=options.max_cycles,
                           processes=options.processes)
        error = ""
    except CadcncError as e:   # the others may still reach: said per setup
        if isinstance(e, InputError):
            raise
        lines, error = {}, f"{type(e).__name__}: {e}"
    keys = line_keys(lines, samples, job)
    blocked = [Skipped(pair, NO_STRETCH, "a third face or the shank is in the way at every "
                       "reach sample") for pair in {*balls.runs, *(c.faces for c in balls.stepped)}
               if pair not in lines]
    run = SetupRun(setup, sp, Program(sub, [], balls.skipped + blocked), len(keys),
                   error=error, sampled=len(keys))
    return run, keys


def _computed(run: SetupRun, samples: dict, job: Job, options: RunOptions) -> set:
    """Compute ``run``'s program (into it) and return the positions it reaches."""
    sub = run.program.job
    try:
        program = operation_of(sub).plan(run.part, sub, options)   # the Pencil's planner
        error = ""
    except NothingToCutError as e:
        program, error = Program(sub), str(e)
    except CadcncError as e:   # the others may still reach: said per setup
        if isinstance(e, InputError):
            raise
        program, error = Program(sub), f"{type(e).__name__}: {e}"
    run.keys = cut_keys(in_part_coordinates(program, setup_in(run.part)), samples, job)
    reached = set().union(*run.keys) if run.keys else set()
    reached.discard(None)
    run.program, run.error, run.reached, run.computed = program, error, len(reached), True
    return reached


def _fewest(reach: list[set], universe: set) -> tuple[list[int], int]:
    """Indices of the fewest sets covering ``universe`` (the most positions in total among
    those, then candidate order), ordered by decreasing reach; and the subsets checked."""
    checked = 0
    for k in range(0 if not universe else 1, len(reach) + 1):
        best = None
        for combo in itertools.combinations(range(len(reach)), k):
            checked += 1
            if set().union(*(reach[i] for i in combo)) >= universe:
                score = sum(len(reach[i]) for i in combo)
                if best is None or score > best[0]:
                    best = (score, combo)
        if best is not None:
            return sorted(best[1], key=lambda i: (-len(reach[i]), i)), checked
    return [], checked


def _unreached(samples: dict, universe: set, runs: list[SetupRun]) -> list:
    """(faces, count, reasons) of the edge positions no candidate reaches: per corner no
    setup cuts at all, each reason with the axes that give it; then, as faces (0, 0), the
    positions at the ends of corners that are cut (where a third face or the shank stops
    every ball: the stretches' limits)."""
    out, ends = [], 0
    for pair, pts in samples.items():
        missing = sum((pair, k) not in universe for k in range(len(pts)))
        if not missing:
            continue
        if missing < len(pts):
            ends += missing
            continue
        why: dict[str, list[str]] = {}
        for r in runs:
            reasons = sorted({s.reason for s in r.program.skipped
                              if tuple(sorted(s.faces)) == pair}) or [
                r.error or "no corner found"]
            for reason in reasons:
                why.setdefault(reason, []).append(r.setup.name)
        out.append((pair, missing, "; ".join(f"{k} ({' '.join(v)})" for k, v in why.items())))
    if ends:
        out.append(((0, 0), ends, "at the ends of corners that are cut: beyond every "
                                  "stretch's limits (a third face or the shank)"))
    return out


def _trimmed(run: SetupRun, keys: list[list], taken: set, overlap: float) -> Program:
    """``run``'s program without the points of positions already cut (module doc)."""
    pieces, skipped = [], list(run.program.skipped)
    for cut, point_keys in zip(run.program.cuts, keys):
        new = np.array([k is None or k not in taken for k in point_keys])
        if overlap > 0 and new.any():
            s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(cut.points, axis=0),
                                                                axis=1))])
            near = np.abs(s[:, None] - s[new][None, :]).min(axis=1) <= overlap
            new = new | near
        for i, j in true_runs(new):
            if j - i >= 2:
                pieces.append(CutSegment(_piece(cut.path, i, j), cut.edge, cut.stretch,
                                         at_limit=True))
    job, part = run.program.job, run.part
    z_safe = safe_height(part, job)
    segments, unreachable, _ = entered_program_segments(
        part, job, pieces, z_safe, join=CHAIN_GAP,
        order=lambda items: order_cuts(items, CHAIN_GAP))
    return Program(job, segments, skipped + unreachable, list(run.program.notes))


def _piece(path, i: int, j: int):
    """Points i..j-1 of a toolpath as one of its own (its per-point arrays sliced)."""
    n = len(path.points)
    per_point = {f.name: getattr(path, f.name)[i:j] for f in fields(path)
                 if isinstance(getattr(path, f.name), np.ndarray)
                 and len(getattr(path, f.name)) == n}
    per_point["steps"] = np.concatenate([[0.0], per_point["steps"][1:]])
    bounds = None if path.bounds is None else tuple(
        replace(b, **{f.name: getattr(b, f.name)[i:j] for f in fields(b)}) for b in path.bounds)
    return replace(path, **per_point, bounds=bounds,
                   stop_reason=path.stop_reason if j == n else TRIMMED,
                   stop_detail=path.stop_detail if j == n else
                   "an earlier setup cuts on from here")


def axis_tag(setup: Setup) -> str:
    """The suffix of a setup's output names: "+Z", "-X", ... or "axis" and its components."""
    return setup.name if setup.name in PRINCIPAL_AXES else "axis" + axis_name(
        tuple(setup.axis)).replace(" ", "")
