"""The candidate setups' reach from samples: where a ball of each tool axis can sit in the
part's corners, judged without cutting them (issue 37).

:func:`~cadcnc.ops.pencil.fewest_setups.pencil_setups` chooses its setups from these
samples and computes the full programs (stretch search, stepping, entries, links) of the
chosen setups only. The samples are the chooser's own positions: along every concave edge
of a corner the pencil cuts, one every ``spacing`` mm of arc length, the ball's tangency in
the plane normal to the edge there, solved and judged as the stretch search judges its
samples (:class:`~cadcnc.ops.path.feasibility.Feasibility`), seeded along the edge as it is;
a blend corner's along its rail. What does not depend on the axis (the tangency, the
trims, tangent faces, curvature) is judged once, in part coordinates
(:func:`ball_samples`); then, per setup, the third faces and the shank along its axis
(the pair's guard, in the setup): every STRIDE-th position of a run and both its ends,
and every position between two that differ (:func:`axis_reach`). A blend corner with no
single rail is cut by the stepper from seed to seed, per setup, as the pencil cuts it.
Each corner gives its feasible ball centres as polylines (part coordinates), which the
chooser keys to positions as it keys a cut's points.

What samples do not see: the entries (a cut no entry reaches counts in the samples, not in
the program), a gap the stepper finds between two samples, a clash or a clear stretch
shorter than the STRIDE positions between two judged alike, a stretch shorter than the
spacing between two infeasible samples, and a cut's last points past its last feasible
sample (a stretch's limit lies between two samples; beyond the middle its points count
the next position: on bm2_ec_lever-A.stp, R 3, the samples reach 1 to 4 positions fewer
than the programs, of 728 to 1876). The chooser takes the chosen setups' reach from their
programs and chooses again where they differ.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ...core.errors import CadcncError
from ...core.job import Job, PairPath
from ...geometry.edge_curve import EdgeCurve
from ...geometry.part import CONCAVE, Part
from ...guard import guard_for
from ...parallel.tasks import on_workers
from ...program.program import Skipped
from ..path.feasibility import Feasibility, Sample
from ..path.pair_program import NO_STRETCH
from ..path.stretches import edge_stretches, pair_stretches, reseeded
from .corners import BLEND, EDGE, Corner, find_corners
from .pencil_program import blend_cut, rail_refs, rails_back

STRIDE = 4
"""Positions between two whose shank and third faces are judged (both ends of a run too);
between two judged alike the positions are taken alike, between two that differ every one
is judged."""


@dataclass
class BallSamples:
    """The positions where the ball fits whatever the axis (tangency, trims, tangent
    faces, curvature): per pair of faces, runs of neighbouring ones as (M, 3) centres,
    part coordinates; the blend corners each setup cuts with the stepper (``stepped``);
    the corners that reach nothing and why (``skipped``, as a program lists them); and
    the ball positions solved (``samples``)."""

    runs: dict[tuple[int, int], list[np.ndarray]] = field(default_factory=dict)
    stepped: list[Corner] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    samples: int = 0


def ball_samples(part: Part, job: Job, counts: dict, spacing: float, *,
                 processes: int | None = 1) -> BallSamples:
    """The axis-free samples of a Pencil ``job`` on ``part`` (part coordinates): module
    doc. ``counts``: per pair, per concave edge index, the number of positions along it
    (the chooser's, so that both grids are one); ``spacing``: mm between positions along
    a blend's rail; ``processes``: processes sampling the pairs (None: every core)."""
    tool = job.tool
    faces = None if job.operation.faces is None else set(job.operation.faces)
    corners = find_corners(part, tool.radius, tool.allowance, faces, job.tolerances)
    out = BallSamples(skipped=[c.skipped() for c in corners if not c.cut])
    groups: dict = {}   # one task per pair
    for corner in corners:
        if corner.cut and corner.kind == BLEND and len(corner.rails) != 1:
            out.stepped.append(corner)
        elif corner.cut:
            groups.setdefault(corner.faces, []).append(corner)
    portable = (lambda c: c) if processes == 1 else (lambda c: rail_refs(part, c))
    tasks = [(job, [portable(c) for c in cs], counts.get(pair, {}), spacing)
             for pair, cs in groups.items()]
    sizes = [sum(c.length for c in cs) for cs in groups.values()]
    for pair, runs, skipped, n in on_workers(_pair_samples, tasks, part, processes,
                                             None, "the reach samples of pair", None, sizes):
        if runs:
            out.runs[pair] = runs
        out.skipped += skipped
        out.samples += n
    return out


def _pair_samples(part: Part, task, beat=None) -> tuple:
    """``(pair, runs, skipped, samples solved)`` of one pair's corners;
    :func:`~cadcnc.parallel.tasks.on_workers`' task."""
    job, corners, counts, spacing = task
    pair = corners[0].faces
    runs: list[np.ndarray] = []
    skipped: list[Skipped] = []
    judged = 0
    for corner in corners:
        corner = rails_back(part, corner)
        cjob = replace(job, operation=PairPath(faces=pair, edge=corner.edge))
        edge = None if corner.edge is None else corner.edge + 1
        try:
            feas = Feasibility(part.face(pair[0]), part.face(pair[1]), cjob, None)
            found = _runs(feas, corner, counts, spacing)
            judged += feas.samples
        except CadcncError as e:
            skipped.append(Skipped(pair, "failed", f"{corner.kind} corner: {e}", edge))
            continue
        if not found:
            skipped.append(Skipped(pair, NO_STRETCH, "no ball position touching both "
                                   "faces within them at the reach samples", edge))
        runs += found
    return pair, runs, skipped, judged


def _runs(feas: Feasibility, corner: Corner, counts: dict,
          spacing: float) -> list[np.ndarray]:
    """The ball-feasible centres along an edge corner's edge (``counts[edge]`` samples,
    ends included) or a blend corner's rail (every ``spacing`` mm), as runs."""
    if corner.kind == EDGE:
        i, j = corner.faces
        edges = [e for e in feas.s1.part.shared_edges(i, j) if e.edge_class == CONCAVE]
        curve = EdgeCurve(edges[corner.edge])
        n = counts[corner.edge]
    else:
        curve = EdgeCurve(corner.rails[0])
        n = max(int(math.ceil(curve.length / spacing)), 1) + 1
    last: Sample | None = None
    runs: list[list] = [[]]
    for s in np.linspace(0.0, curve.length, n):   # seeded from the last sample if solved
        seed = last if last is not None and last.tangency is not None else None
        last = x = reseeded(feas, curve, float(s), seed)
        if x.ok:
            runs[-1].append(x.tangency.p)
        elif runs[-1]:
            runs.append([])
    return [np.array(r) for r in runs if r]


def axis_reach(part: Part, job: Job, balls: BallSamples, *, max_cycles: int,
               processes: int | None = 1) -> dict[tuple[int, int], list[np.ndarray]]:
    """Per pair, the polylines (part coordinates) of ``balls``' centres the shank and
    the third faces also clear in the setup of ``part`` (the part turned into ``job``'s
    axis), and the stepper's cuts of its blend corners: module doc."""
    setup = getattr(part, "setup", None)
    to_setup = (lambda p: p) if setup is None else setup.to_setup
    to_part = (lambda p: p) if setup is None else setup.to_part
    portable = (lambda c: c) if processes == 1 else (lambda c: rail_refs(part, c))
    tasks = [(job, pair, [to_setup(r) for r in runs], [], max_cycles)
             for pair, runs in balls.runs.items()]
    tasks += [(job, c.faces, [], [portable(c)], max_cycles) for c in balls.stepped]
    sizes = [sum(len(r) for r in t[2]) + 100 * len(t[3]) for t in tasks]
    out: dict = {}
    for pair, lines in on_workers(_pair_clear, tasks, part, processes, None,
                                  "the reach samples of pair", None, sizes):
        out.setdefault(pair, []).extend(to_part(line) for line in lines)
    return out


def _pair_clear(part: Part, task, beat=None) -> tuple:
    """``(pair, polylines)``: the runs of one pair that its guard clears (setup
    coordinates), or its blend corners' stepper cuts; on_workers' task."""
    job, pair, runs, stepped, max_cycles = task
    cjob = replace(job, operation=PairPath(faces=pair))
    lines: list[np.ndarray] = []
    try:
        guard = guard_for(part, pair, cjob)
        for run in runs:
            ok = _cleared(guard, run)
            lines += [run[a:b] for a, b in true_runs(ok)]
        for corner in stepped:
            cut = blend_cut(part.face(pair[0]), part.face(pair[1]), cjob,
                            rails_back(part, corner), guard, max_cycles, lambda *_: None)
            if len(cut.points) >= 2:
                lines.append(cut.points)
    except CadcncError:
        return pair, []   # the program says why, should this setup be chosen
    return pair, lines


def _cleared(guard, run: np.ndarray) -> np.ndarray:
    """Whether the guard clears each centre of ``run``: judged every STRIDE-th and at
    both ends, and everywhere between two judged that differ (module doc)."""
    n = len(run)
    ok = np.zeros(n, dtype=bool)
    known = np.zeros(n, dtype=bool)

    def judge(k: int) -> bool:
        if not known[k]:
            ok[k], known[k] = guard.clears(run[k]), True
        return bool(ok[k])

    marks = sorted(set(range(0, n, STRIDE)) | {n - 1})
    for a, b in zip(marks, marks[1:]):
        stack = [(a, b)]
        while stack:
            lo, hi = stack.pop()
            if hi - lo < 2:
                judge(lo), judge(hi)
            elif judge(lo) == judge(hi):
                ok[lo + 1:hi], known[lo + 1:hi] = ok[lo], True
            else:
                mid = (lo + hi) // 2
                stack += [(mid, hi), (lo, mid)]
    judge(marks[0])
    return ok


def true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) of every run of True in ``mask``."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    return list(zip(edges[::2], edges[1::2]))


def stretch_lines(part: Part, job: Job, pair: tuple[int, int], *,
                  max_cycles: int) -> list[np.ndarray]:
    """The polylines (part coordinates) of the stretches the pencil's own search finds
    on the corners of ``pair`` in the setup of ``part`` (the samples and both limits of
    each; a blend corner with no single rail: the stepper's cut): a finer look than the
    samples' where the chooser needs one."""
    tool = job.tool
    faces = None if job.operation.faces is None else set(job.operation.faces)
    corners = [c for c in find_corners(part, tool.radius, tool.allowance, faces,
                                       job.tolerances) if c.cut and c.faces == pair]
    cjob = replace(job, operation=PairPath(faces=pair))
    s1, s2 = part.face(pair[0]), part.face(pair[1])
    lines, found, of_pair = [], [], None
    try:
        guard = guard_for(part, pair, cjob) if corners else None
        feas = Feasibility(s1, s2, cjob, guard)
        for c in corners:
            if c.kind == EDGE:
                of_pair = of_pair or pair_stretches(s1, s2, cjob, guard, feas=feas)
                found.append(of_pair[c.edge])
            elif len(c.rails) == 1:
                found.append(edge_stretches(feas, c.rails[0], 0))
            else:
                cut = blend_cut(s1, s2, cjob, c, guard, max_cycles, lambda *_: None)
                lines += [cut.points] if len(cut.points) >= 2 else []
    except CadcncError:
        return []
    for e in found:
        lines += [_stretch_points(e.samples, st) for st in e.stretches]
    setup = getattr(part, "setup", None)
    return lines if setup is None else [setup.to_part(line) for line in lines]


def _stretch_points(samples: list, st) -> np.ndarray:
    """A stretch's centres: its start limit, its feasible samples, its end limit (all of
    them for a closed edge feasible all around)."""
    ok = [x for x in samples if x.ok]
    if st.closed:
        inside = ok
    elif st.start.s <= st.end.s:
        inside = [x for x in ok if st.start.s <= x.s <= st.end.s]
    else:   # across a closed edge's seam
        inside = [x for x in ok if x.s >= st.start.s] + [x for x in ok if x.s <= st.end.s]
    return np.array([st.start.p] + [x.tangency.p for x in inside] + [st.end.p])
