"""Bounded landing: the longest fraction of a step that passes every stop rule, in few trials.

When a full step breaks a rule, the stepper shortens it to the rule's limit. Each trial is a
whole cycle, so their number is bounded (``MAX_TRIALS`` including the failed full step, to
fit inside one interpolation period). Where the broken rule has a continuous margin
(curvature 1 - R' k, singularity ratio, carried error, a guard's clearance in mm) the limit
is the margin's zero, found by regula falsi with the Illinois modification (superlinear on a
smooth margin) and a bisection guard (a trial that does not halve the bracket twice running
is followed by a bisection). Yes/no rules (a contact's trim state, a singular correction
system) have no margin: those are bisected. Kernel-free.
"""

from __future__ import annotations

import math
from typing import Callable

MAX_TRIALS = 24
"""Trial cycles a stop may take, the failed full step included."""
LANDING_TOL = 1e-12
"""mm: the landing bracket's width on the step (where the trials allow it)."""


def land(trial: Callable[[float], tuple[bool, float, bool]], margin_lo: float,
         margin_hi: float, trials: int, width: float) -> tuple[float, int]:
    """Largest passing fraction ``lo`` of the step in [0, 1) found, and the trials used.

    ``trial(s)`` runs the cycle with step fraction s and returns (passed, margin,
    rule_changed): the margin of the rule being landed on (NaN when it has none) and whether
    a failure came from another rule than the last one (the margins then stop being
    comparable). ``margin_lo`` is the margin at the current point (s = 0; NaN if unknown),
    ``margin_hi`` the failed full step's (s = 1). At most ``trials``
    calls; stops once the bracket [lo, hi] is at most ``width`` (a fraction of the step).
    ``lo`` is 0.0 when no trial passed.
    """
    lo, hi = 0.0, 1.0
    g_lo, g_hi = margin_lo, margin_hi
    kept = 0          # +1: hi kept by the last trial (lo moved), -1: lo kept
    widths = [2.0, 2.0]   # the bracket before the last two trials
    used = 0
    while used < trials and hi - lo > width:
        w = hi - lo
        bisect = (not (g_lo >= 0.0 and g_hi < 0.0 and math.isfinite(g_lo - g_hi))
                  or w > 0.5 * widths[0])
        if bisect:
            s = lo + 0.5 * w
        else:  # regula falsi, kept a half-width inside the ends so the bracket closes
            s = lo + w * g_lo / (g_lo - g_hi)
            s = min(max(s, lo + 0.5 * width), hi - 0.5 * width)
        passed, g, changed = trial(s)
        used += 1
        widths = [widths[1], w]
        if passed:
            lo, g_lo = s, g
            if kept == 1:
                g_hi *= 0.5    # Illinois: the same end kept twice, halve its margin
            kept = 1
        else:
            hi, g_hi = s, g
            if changed:
                g_lo = math.nan
            elif kept == -1:
                g_lo *= 0.5
            kept = -1
    return lo, used
