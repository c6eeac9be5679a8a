"""Every feasible stretch of a corner: where along a shared concave edge the ball can sit.

A ball position is feasible or not as :class:`~.feasibility.Feasibility` judges it
(tangency, trims, the faces' angle, curvature, the ball's and the shank's clearance).
A *stretch* is a maximal connected piece of the offset intersection curve made of
feasible positions.

Method: tangency samples anchored on planes normal to the edge, every ``spacing`` mm of
edge (0.4 mm, at least 9 per edge) and continued ``R' + 1`` mm beyond each end of an
open edge along its end tangent; a sample interval whose centres are more than
``MAX_CHORD`` apart is split until they are not. Each change feasible/infeasible
between neighbouring samples is located by a root search on the failing rule's signed
margin (:mod:`.limit_search`; bisection for the rules without one) until the feasible and
the infeasible centres are less than ``Tolerances.stretch_limit`` (a tenth of the gouge
limit) apart; the limit is the feasible one, its rule the one that fails beside it.

Guarantee: neighbouring samples' centres are at most MAX_CHORD = 0.45 mm apart, so a
stretch (or a gap between stretches) can be missed only if it is shorter than the
curve between two samples: under 0.5 mm wherever the curve turns less than ~50 deg
over 0.45 mm. Intervals where a sample has no tangency, or could not be refined to
MAX_CHORD, are counted in ``EdgeStretches.missed`` (a stretch of any length may hide
there); they are never reported as feasible. A gap the samples miss is found by the
stepper (every 0.1 mm step) and, when this judge confirms it, ends the stretch there
(:mod:`.stretch_split`): an expected end, not a stop short.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ...core.job import Job
from ...core.tolerances import DEFAULT
from ...geometry.edge_curve import EdgeCurve
from ...geometry.part import CONCAVE
from ...guard import guard_for
from ...guard.clearance import ClearanceGuard
from ...interp.stepper import Tangency
from .centre_curve import polyline_length, travel_direction
from .feasibility import (
    BOUNDARY,
    ONE_SIDED,
    REASONS,
    TANGENT,
    UNSOLVED,
    Feasibility,
    Sample,
)
from .limit_search import bisect, root_limit

SPACING = 0.4       # mm of edge between samples (refined to MAX_CHORD of centres)
MIN_SAMPLES = 9     # per edge
MAX_CHORD = 0.45    # mm: neighbouring sample centres are refined to at most this apart
LIMIT_TOL = 1e-7    # mm: the reference bisection's accuracy (bisect_limit), and the
#                     anchors' where the failing side has no centre (the root search)
MAX_SPLITS = 6      # halvings of a sample interval whose centres are too far apart

SEARCH = "search"       # the stretch goes on past the searched extension of the edge
CLOSED = "closed"       # a closed edge feasible all around

RESEED = (BOUNDARY, TANGENT, UNSOLVED)
"""Rules a seeded sample may fail on the wrong branch (two offset intersection curves
near each other, where faces turn tangent). A sample on the edge failing another rule than
its neighbour is solved again from the anchor, and kept if feasible: the stretches do not
depend on where the chain started (0.35 % more samples on 64 pairs of r0901_ec)."""

@dataclass(frozen=True)
class Limit:
    """One end of a stretch: the last feasible position and the rule that fails past it."""

    tangency: Tangency
    rule: str        # BOUNDARY, COLLISION, CURVATURE, TANGENT, UNSOLVED, SEARCH, CLOSED
    detail: str
    s: float         # arc length of the anchor along the edge, mm

    @property
    def p(self) -> tuple[float, float, float]:
        return self.tangency.p


@dataclass(frozen=True)
class Stretch:
    """A maximal feasible piece of the offset intersection curve along edge ``edge``.

    ``direction`` is the cut's sense at the start (towards the next centre, see
    :func:`travel_direction`; the path runs start to end);
    ``length`` the centre polyline's length over the samples, mm.
    """

    edge: int
    start: Limit
    end: Limit
    direction: tuple[float, float, float]
    length: float
    closed: bool = False


@dataclass
class EdgeStretches:
    """The stretches of one shared concave edge (0-based index among the pair's concave
    edges), its samples, the intervals where a stretch may have been missed, and, when
    it has no stretch, the reason."""

    edge: int
    length: float = 0.0   # mm of edge; samples with 0 <= s <= length lie on the edge itself
    stretches: list[Stretch] = field(default_factory=list)
    samples: list[Sample] = field(default_factory=list)
    missed: int = 0
    why: str = ""         # why the edge was not searched (a degenerate edge)
    curve: EdgeCurve | None = None      # the curve the samples are anchored on
    judge: "Feasibility | None" = None  # the judge of its positions (stretch_split reuses it)

    @property
    def refusal(self) -> str | None:
        """Why no position of this edge is feasible (the rule failing at most samples on
        the edge itself, with an example), or None when it has a stretch."""
        if self.stretches:
            return None
        if self.why or not self.samples:
            return f"edge {self.edge + 1}: {self.why or 'not searched'}"
        on_edge = [x for x in self.samples if 0.0 <= x.s <= self.length] or self.samples
        counts: dict[str, int] = {}
        for x in on_edge:
            counts[x.rule] = counts.get(x.rule, 0) + 1
        rule = max(counts, key=counts.get)
        failing = [x for x in on_edge if x.rule == rule]
        example = failing[len(failing) // 2]   # the middle one: away from the edge's ends
        if self.judge is not None:
            example = self.judge.exact(example)
        return (f"edge {self.edge + 1}: no feasible ball position: {REASONS.get(rule, rule)}"
                f" ({example.detail}; at {counts[rule]} of {len(on_edge)} samples on the "
                "edge)")


def edge_stretches(feas: Feasibility, shared_edge, edge: int,
                   spacing: float = SPACING, extend: tuple[bool, bool] = (True, True)
                   ) -> EdgeStretches:
    """Every stretch along one shared concave edge (see the module's method).

    ``extend``: whether to search past the edge's start and end; not where another
    concave edge of the same pair continues it (that edge's own search covers it, and two
    cuts would overlap)."""
    curve = EdgeCurve(shared_edge)
    if not curve.closed and not curve.length >= feas.tol.gouge:
        return EdgeStretches(edge, curve.length, why=(
            f"degenerate edge of {curve.length:.3g} mm, shorter than the gouge limit "
            f"{feas.tol.gouge:g} mm: not a corner"))
    ext = 0.0 if curve.closed else max(feas.offsets) + 1.0
    n = max(MIN_SAMPLES, int(math.ceil(curve.length / spacing)) + 1)
    grid = np.linspace(0.0, curve.length, n)
    if curve.closed:
        grid = grid[:-1]
    # past the ends at the search's own spacing, however short the edge (a 1 um edge's
    # in-edge step would give tens of thousands of samples)
    step = max(grid[1] - grid[0], spacing)
    k_ext = int(math.ceil(ext / step)) if ext > 0 else 0
    k_lo, k_hi = (k_ext if go else 0 for go in extend)
    grid = np.concatenate([-step * np.arange(k_lo, 0, -1), grid,
                           curve.length + step * np.arange(1, k_hi + 1)])
    out = EdgeStretches(edge, curve.length, curve=curve, judge=feas)
    samples: list[Sample] = []
    for s in grid:   # each seeded from the last solved sample: stays on one branch
        last = next((x for x in reversed(samples[-1:]) if x.tangency is not None), None)
        samples.append(reseeded(feas, curve, float(s), last))
    samples = _refine(feas, curve, samples, out)
    out.samples = samples
    out.stretches = _stretches(feas, curve, samples, edge)
    return out


def reseeded(feas: Feasibility, curve: EdgeCurve, s: float, last: Sample | None) -> Sample:
    """The (quick) sample at ``s`` seeded from ``last``, or from the anchor (see RESEED)."""
    x = sample_at(feas, curve, s, last, quick=True)
    if last is None or x.rule not in RESEED or x.rule == last.rule or not 0 <= s <= curve.length:
        return x
    return max(x, sample_at(feas, curve, s, None, quick=True), key=lambda y: y.ok)


def sample_at(feas: Feasibility, curve: EdgeCurve, s: float, seed: Sample | None,
              quick: bool = False) -> Sample:
    """The sample at arc length ``s`` seeded from ``seed`` (else, or when that fails to
    solve, from the anchor); ``quick``: see :meth:`Feasibility.sample`."""
    anchor, tangent = curve.point_tangent(s)
    tan = seed.tangency if seed is not None else None
    got = feas.sample(s, anchor, tangent, tan, quick)
    if got.rule == UNSOLVED and tan is not None:   # the seed may mislead: try the anchor
        got = feas.sample(s, anchor, tangent, None, quick)
    return got


def _refine(feas, curve, samples: list[Sample], out: EdgeStretches) -> list[Sample]:
    """Split intervals whose centres are more than MAX_CHORD apart (to SPACING /
    2**MAX_SPLITS of edge); count in ``out.missed`` the intervals where a stretch may
    hide: still too far apart, or no tangency at either end on the edge itself."""
    floor = SPACING / 2 ** MAX_SPLITS
    result = [samples[0]]
    for b in samples[1:]:
        stack = [b]
        while stack:
            a, b = result[-1], stack[-1]
            if a.tangency is None or b.tangency is None:
                if a.tangency is None and b.tangency is None and b.s > 0.0 \
                        and a.s < curve.length:
                    out.missed += 1
            elif np.linalg.norm(np.subtract(a.tangency.p, b.tangency.p)) > MAX_CHORD:
                if b.s - a.s > floor:
                    # seeded from a's tangency, feasible or not, as the grid is: from the
                    # anchor alone Newton may land on another branch of the curve (millimetres
                    # away), and every halving would land there again
                    stack.append(sample_at(feas, curve, 0.5 * (a.s + b.s), a, quick=True))
                    continue
                out.missed += 1
            result.append(stack.pop())
    return result


def locate_limit(feas, curve, good: Sample, bad: Sample) -> tuple[Sample, Sample]:
    """(last feasible, first failing) between a feasible and an infeasible sample: a root
    search on the failing rule's margin (:func:`.limit_search.root_limit`) until their
    centres are ``Tolerances.stretch_limit`` apart (the anchors LIMIT_TOL where the failing
    side has no centre)."""
    tol = getattr(feas, "tol", DEFAULT).stretch_limit
    bad = feas.exact(bad)
    good, bad, _ = root_limit(lambda s, seed: sample_at(feas, curve, s, seed), good, bad,
                              tol, LIMIT_TOL, ONE_SIDED,
                              () if curve.closed else (0.0, curve.length))
    return good, bad


def bisect_limit(feas, curve, good: Sample, bad: Sample) -> tuple[Sample, Sample]:
    """The reference: the search before the root search (:func:`.limit_search.bisect`,
    centres LIMIT_TOL apart); tests compare the two."""
    return bisect(lambda s, seed: sample_at(feas, curve, s, seed), good, bad, LIMIT_TOL)


def _limit(feas, curve, good: Sample, bad: Sample | None) -> Limit:
    """The limit between a feasible sample and its infeasible neighbour (None: the end of
    the searched extension). On a closed edge the neighbour across the seam is moved by
    one period of arc length, so that the bisection runs between the two."""
    if bad is None:
        return Limit(good.tangency, SEARCH, "the stretch goes on past the searched "
                     "extension of the edge", good.s)
    if curve.closed and abs(bad.s - good.s) > 0.5 * curve.length:
        bad = replace(bad, s=bad.s + math.copysign(curve.length, good.s - bad.s))
    good, bad = locate_limit(feas, curve, good, bad)
    return Limit(good.tangency, bad.rule, bad.detail, good.s)


def _stretches(feas, curve, samples: list[Sample], edge: int) -> list[Stretch]:
    """Runs of feasible samples, each with both limits located."""
    ok = [x.ok for x in samples]
    if curve.closed and all(ok):
        first = samples[0]
        lim = Limit(first.tangency, CLOSED, "feasible all around the closed edge", first.s)
        pts = [x.tangency for x in samples + [first]]
        return [Stretch(edge, lim, lim, first.tangent, polyline_length(pts), True)]
    order = list(range(len(samples)))
    if curve.closed:   # start the walk at an infeasible sample, wrapping around
        k = ok.index(False)
        order = order[k:] + order[:k]
    runs, run = [], []
    for idx in order:
        if ok[idx]:
            run.append(idx)
        elif run:
            runs.append(run)
            run = []
    if run:
        runs.append(run)
    out = []
    n = len(samples)
    for run in runs:
        first, last = run[0], run[-1]
        before = (first - 1) % n if curve.closed or first > 0 else None
        after = (last + 1) % n if curve.closed or last < n - 1 else None
        start = _limit(feas, curve, samples[first], None if before is None else
                       samples[before])
        end = _limit(feas, curve, samples[last], None if after is None else samples[after])
        pts = [start.tangency] + [samples[i].tangency for i in run] + [end.tangency]
        out.append(Stretch(edge, start, end, travel_direction(pts, samples[first].tangent),
                           polyline_length(pts)))
    return out


def pair_stretches(s1, s2, job: Job, guard: ClearanceGuard | None = None,
                   spacing: float = SPACING, feas: Feasibility | None = None
                   ) -> list[EdgeStretches]:
    """Every stretch of every shared concave edge of two faces of one part. ``guard``
    defaults to the job's tool (R', shank length, tolerance ``hit``); ``feas``: the judge
    of positions to use (one whose ``beat`` reports progress), else built here."""
    part = s1.part
    edges = [e for e in part.shared_edges(s1.number, s2.number) if e.edge_class == CONCAVE]
    if feas is None:
        if guard is None:
            guard = guard_for(part, (s1.number, s2.number), job)
        feas = Feasibility(s1, s2, job, guard)
    return [edge_stretches(feas, e, k, spacing, (not _continued(e.start, e, edges),
                                                 not _continued(e.end, e, edges)))
            for k, e in enumerate(edges)]


JOIN = 1e-6  # mm: edge ends closer than this are one vertex


def _continued(point, edge, edges) -> bool:
    """Whether another of the pair's concave edges starts or ends at ``point``."""
    p = np.asarray(point, dtype=float)
    return any(min(np.linalg.norm(p - np.asarray(o.start)), np.linalg.norm(
        p - np.asarray(o.end))) <= JOIN for o in edges if o is not edge and not o.closed)
