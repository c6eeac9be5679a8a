"""A gap the stretch search stepped over, found by the stepper: the stretch split there.

The search (:mod:`.stretches`) judges a corner every 0.4 mm of edge, so a gap shorter
than that (a contact grazing a hole in its face, a thin obstacle) may lie between two
feasible samples: the stretch runs across it. The stepper checks every step (0.1 mm) and
stops at such a gap, located to ~1e-8 mm. :func:`split_at_stop` asks the search's own
judge (the same classifier, curvature rule and guard) about the positions just past the
stop: when one is infeasible, the gap is real and the stretch ends there (its end limit
located as the search locates every limit), and what follows the gap is a new stretch
from the first feasible position past it. When the judge finds every position past the
stop feasible, it does not confirm the stop: nothing is split, and the cut stays a stop
short (partial). Arc lengths ``s`` along the edge, mm.
"""

from __future__ import annotations

import numpy as np

from .centre_curve import polyline_length, travel_direction
from .feasibility import UNSOLVED, Sample
from .stretches import EdgeStretches, Limit, Stretch, locate_limit, sample_at

FIRST_PROBE = 1e-7   # mm of edge past the stop: the first position judged (then doubled)
BISECTIONS = 60      # halvings locating the stop's arc length between two samples


def split_at_stop(found: EdgeStretches, st: Stretch, stop
                  ) -> tuple[Stretch, list[Stretch]] | None:
    """(the stretch ending at the gap the stepper stopped at, [the rest after the gap])
    for a cut of ``st`` that stopped at centre ``stop`` (3,) mm before its end; None when
    the judge finds no infeasible position there (the stop is not a gap of the corner)."""
    feas, curve = found.judge, found.curve
    if feas is None or curve is None or st.closed:
        return None
    run = [x for x in found.samples if st.start.s < x.s < st.end.s and x.ok]
    s_stop = _arc_length(curve, [st.start.s] + [x.s for x in run] + [st.end.s], stop)
    if s_stop is None:
        return None
    before = [x for x in run if x.s <= s_stop]
    after = [x for x in run if x.s > s_stop]
    seed = before[-1] if before else sample_at(feas, curve, st.start.s, None)
    here = sample_at(feas, curve, s_stop, seed)
    good, bad = (here, None) if here.ok else (seed, here)
    reach = (after[0].s if after else st.end.s) - s_stop
    step = FIRST_PROBE
    while bad is None and step < reach:
        x = sample_at(feas, curve, s_stop + step, good)
        if not x.ok:
            bad = x
        step *= 2.0
    if bad is None or bad.rule == UNSOLVED or not good.ok:
        return None
    end_good, end_bad = locate_limit(feas, curve, good, bad)
    head = Stretch(st.edge, st.start, Limit(end_good.tangency, end_bad.rule,
                                            end_bad.detail, end_good.s), st.direction,
                   _length(st.start, [x for x in run if x.s < end_good.s], end_good))
    resume = next((x for x in after if x.s > end_bad.s), None)
    if resume is None:
        resume = sample_at(feas, curve, st.end.s, end_bad)
        if not resume.ok or resume.s <= end_bad.s:
            return head, []
    start_good, start_bad = locate_limit(feas, curve, resume, end_bad)
    later = [x for x in run if x.s > start_good.s]
    rest = Stretch(st.edge, Limit(start_good.tangency, start_bad.rule, start_bad.detail,
                                  start_good.s), st.end,
                   travel_direction([start_good.tangency] + [x.tangency for x in later]
                                    + [st.end.tangency], start_good.tangent),
                   _length(start_good, later, st.end))
    return head, [rest]


def _length(first, samples: list[Sample], last) -> float:
    """The centre polyline's length from limit (or sample) ``first`` over ``samples`` to
    ``last``, mm."""
    return polyline_length([first.tangency] + [x.tangency for x in samples]
                           + [last.tangency])


def _arc_length(curve, grid: list[float], p) -> float | None:
    """The arc length s whose anchor plane (through the edge's point at s, normal to its
    tangent) holds centre ``p``: bisection between the two neighbouring values of ``grid``
    (sorted) that bracket it nearest ``p``; None if none does."""
    def side(s: float) -> float:
        a, t = curve.point_tangent(s)
        return float(np.dot(np.subtract(p, a), t))

    signs = [side(s) for s in grid]
    brackets = [k for k in range(len(grid) - 1) if signs[k] >= 0.0 >= signs[k + 1]]
    if not brackets:
        return None
    k = min(brackets, key=lambda k: abs(signs[k]) + abs(signs[k + 1]))
    lo, hi = grid[k], grid[k + 1]
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if side(mid) >= 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
