"""A stretch limit found by a safeguarded root search on the failing rule's signed margin.

Between a feasible sample and an infeasible one (arc lengths ``s`` of their anchors along
the edge), the limit is where the rule failing on the infeasible side changes sign. Each
sample carries the signed margins its verdict already computed (``Sample.margins``: > 0
feasible side, < 0 infeasible, continuous across the limit):

- ``tangent``: |n1 x n2| - ``stretch_tangent_sin`` (dimensionless);
- ``curvature``: 1 + gouge / 2 R' - R' k, the tighter contact's (dimensionless);
- ``collision``: the guard's clearance (mm), exact wherever it is negative, only a
  positive lower bound on the feasible side (its Lipschitz cache spares the exact
  distance there, and no call is added for the search): a one-sided margin.

``boundary`` (the trim classifier answers in/on/out, no distance) and ``unsolved`` (no
centre) have none: those limits are bisected, to the same tolerance.

The search is regula falsi with the Illinois modification on arc length (as
:func:`cadcnc.interp.landing.land`): each trial a quarter-tolerance short of the
interpolant's root (so a limit keeps a margin where the estimate is right) and at least a
half-tolerance inside the bracket's ends (so a trial on the feasible side is followed by
one just past it, and the bracket closes); a bisection whenever there are no two margins
of the same rule, the interpolant leaves the bracket, or the last two trials did not halve
it. For the one-sided collision margin the interpolant uses the infeasible side only: the
secant through its last two margins, or from one the step back by |margin| mm of centre
(the clearance of a third face is 1-Lipschitz in the centre, so that step cannot cross its
zero; where it is steeper, the own-face rule's 2, the trial lands feasible and the bracket
still shrinks). A rule without a margin tries the edge's ends first when they lie in the
bracket (a contact leaves its face where the face ends: one or two trials there), then
bisects. A trial failing another rule than the infeasible end becomes that end, and the
search goes on with that rule's margins (the feasible end has them all).

It stops when the two ends' centres are less than ``tol`` apart (the job's
``Tolerances.stretch_limit``, a tenth of the gouge limit) and returns the feasible end:
nothing infeasible is ever kept as a limit. Where the infeasible end has no centre it
stops when the anchors are ``anchor_tol`` apart. Kernel-free: ``trial(s, seed)`` judges
a position (a ``Sample``); :func:`bisect` is the reference it replaced.
"""

from __future__ import annotations

import math
from typing import Callable

ANCHORS_MET = 1e-12
"""mm of edge: anchors this close are one point, no arc length is left to search."""
MAX_TRIALS = 80
"""Samples one limit may take (the bisection's 22 to 1e-7 mm, twice over, and more)."""


def margin_of(sample, rule: str, one_sided=()) -> float:
    """The sample's signed margin of ``rule``, NaN where it has none (or where the rule is
    ``one_sided`` and the sample feasible: there the margin is only a lower bound)."""
    if not sample.margins or (sample.ok and rule in one_sided):
        return math.nan
    return sample.margins.get(rule, math.nan)


def root_limit(trial: Callable, good, bad, tol: float, anchor_tol: float,
               one_sided=(), hints=(), max_trials: int = MAX_TRIALS
               ) -> tuple[object, object, int]:
    """(last feasible sample, first failing sample, trials used) between ``good``
    (feasible) and ``bad`` (infeasible); the centres of the two are less than ``tol``
    apart (mm), or their anchors ``anchor_tol`` where ``bad`` has no centre (or 1e-12 mm
    of arc length, or ``max_trials`` spent).

    Rules in ``one_sided`` (the guard's clearance, mm of centre) are exact only on the
    infeasible side and at most 1 mm/mm steep in the centre's position: their trial is the
    secant through the last two infeasible margins, or with one only the step of |margin|
    mm of centre towards the feasible end (it cannot cross a 1-Lipschitz margin's zero).
    ``hints``: arc lengths where a limit is likely (the edge's ends: a contact leaving its
    face where the face ends), tried first, like an interpolant's root, by a rule with no
    margin while they lie inside the bracket (two trials each at most).
    """
    lo, hi = good, bad
    rule = hi.rule
    f_lo, f_hi = margin_of(lo, rule, one_sided), margin_of(hi, rule, one_sided)
    failing = [(hi.s, f_hi)]       # the infeasible trials of ``rule`` (one-sided rules)
    kept = 0                       # +1: hi kept by the last trial (lo moved), -1: lo kept
    widths = [math.inf, math.inf]  # |bracket| before the last two trials
    used = 0
    while used < max_trials:
        w = hi.s - lo.s            # signed: the infeasible end may lie either side
        if abs(w) < ANCHORS_MET:
            break
        if hi.tangency is None:
            if abs(w) < anchor_tol:
                break
            tol_s, per_mm = anchor_tol, math.nan
        else:
            chord = _distance(lo.tangency.p, hi.tangency.p)
            if chord < tol:
                break
            per_mm = abs(w) / chord    # arc length per mm of centre, at this bracket
            tol_s = tol * per_mm
        t = math.nan
        inside = [h for h in hints if 0.0 <= (h - lo.s) / w < 1.0]
        if math.isnan(margin_of(hi, rule, one_sided)) and inside:
            t = (inside[0] - lo.s) / w
        elif abs(w) <= 0.5 * widths[0]:   # else the bracket did not halve in two: bisect
            if rule not in one_sided:
                if f_lo >= 0.0 > f_hi and math.isfinite(f_lo - f_hi):
                    t = f_lo / (f_lo - f_hi)    # regula falsi
            else:
                t = _one_sided(failing, lo.s, w, per_mm)
        if 0.0 <= t <= 1.0:
            # a quarter-tolerance short of the estimate (a limit keeps a margin > 0 where
            # the estimate is right), and a half-tolerance inside the ends (so the bracket
            # closes: a trial on the feasible side is followed by one just past it)
            t = min(max(t - 0.25 * tol_s / abs(w), 0.5 * tol_s / abs(w)),
                    1.0 - 0.5 * tol_s / abs(w))
        else:
            t = 0.5
        x = trial(lo.s + t * w, lo)
        used += 1
        widths = [widths[1], abs(w)]
        if x.ok:
            lo, f_lo = x, margin_of(x, rule, one_sided)
            if kept == 1:
                f_hi *= 0.5   # Illinois: the same end kept twice, halve its margin
            kept = 1
        elif x.rule != rule:   # another rule fails first here: search on its margin
            hi, rule = x, x.rule
            f_lo, f_hi = margin_of(lo, rule, one_sided), margin_of(hi, rule, one_sided)
            failing = [(hi.s, f_hi)]
            kept = 0
        else:
            hi, f_hi = x, margin_of(x, rule, one_sided)
            failing.append((hi.s, f_hi))
            if kept == -1:
                f_lo *= 0.5
            kept = -1
    return lo, hi, used


def _one_sided(failing: list, s_lo: float, w: float, per_mm: float) -> float:
    """The trial's place in the bracket (0 at the feasible end, 1 at the infeasible one),
    NaN when there is none, from the infeasible margins alone: the secant through the last
    two, else the Lipschitz step from the last."""
    (s1, f1) = failing[-1]
    if not f1 < 0.0:
        return math.nan
    if len(failing) >= 2:
        s0, f0 = failing[-2]
        if f0 < 0.0 and f0 != f1 and s0 != s1:
            s = s1 - f1 * (s1 - s0) / (f1 - f0)
            return (s - s_lo) / w
    if not math.isfinite(per_mm):
        return math.nan
    return 1.0 + f1 * per_mm / abs(w)   # |f1| mm of centre back from the infeasible end


def bisect(trial: Callable, good, bad, tol: float) -> tuple[object, object]:
    """The reference search (the stretch search's before this module): bisection on arc
    length between ``good`` and ``bad`` until their centres are ``tol`` apart (or the
    anchors 1e-12 mm, or 80 halvings): (last feasible, first failing)."""
    for _ in range(80):
        if bad.tangency is not None and _distance(good.tangency.p, bad.tangency.p) < tol:
            break
        if abs(bad.s - good.s) < ANCHORS_MET:
            break
        mid = trial(0.5 * (good.s + bad.s), good)
        if mid.ok:
            good = mid
        else:
            bad = mid
    return good, bad


def limit_samples(width: float, tol: float) -> int:
    """Samples a limit bracketed ``width`` mm wide costs when bisected to ``tol`` mm (the
    boundary rule's search; a rule with a margin takes fewer): for the work estimate."""
    return max(1, int(math.ceil(math.log2(max(width / tol, 1.0)))))


def _distance(a, b) -> float:
    return math.sqrt((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2)
