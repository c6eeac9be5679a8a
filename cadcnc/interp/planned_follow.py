"""A stepper following a planned arc length per period: a controller's feed plan applied.

``follow(stepper, plan, end, curvature, landing)`` commands each period the step that
closes the gap between the planned length and the distance travelled, blended onto the
distance left to the end over the last stretch (the rule of
:mod:`cadcnc.interp.kernel.follow`). Every position is the stepper's own: the kernel's
accuracy rule, trial cycle and end landing apply to each commanded step as to any
override. On a compiled stepper the loop runs in the kernel (``CompiledStepper.follow``);
on the plain-Python reference it is this module's loop, period by period. No OCCT.
"""

from __future__ import annotations

import math

import numpy as np

from .compiled import CompiledStepper
from .kernel import follow as KF


def follow_args(end, curvature: float, landing: float, period: float) -> np.ndarray:
    """The kernel's ``args``: end point, curvature there (1/mm), landing share, 60 / Ts, Ts."""
    args = np.empty(KF.ARGS)
    args[KF.A_END:KF.A_END + 3] = np.asarray(end, dtype=float)
    args[KF.A_K], args[KF.A_LANDING] = curvature, landing
    args[KF.A_TO_FEED], args[KF.A_PERIOD] = 60.0 / period, period
    return args


def follow(stepper, plan: np.ndarray, end, curvature: float, landing: float) -> np.ndarray:
    """(rows, 3): the centre after each period of ``plan`` ((rows, 3): target length,
    blend weight, length left; see kernel/follow.py). Rows after a stop hold the last
    position; the caller reads ``stepper.stop_reason``."""
    args = follow_args(end, curvature, landing, stepper.period)
    if isinstance(stepper, CompiledStepper):
        return stepper.follow(plan, args)
    out = np.empty((len(plan), 3))
    to_feed = args[KF.A_TO_FEED]
    ex, ey, ez = map(float, end)
    for n, (target, w, left) in enumerate(np.asarray(plan, dtype=float).tolist()):
        if stepper.stop_reason is None:
            f = target - stepper.travelled
            if w > 0.0:
                x, y, z = stepper.p
                d = math.sqrt((ex - x) ** 2 + (ey - y) ** 2 + (ez - z) ** 2)
                f = (1.0 - w) * f + w * (d * (1.0 + curvature * curvature * d * d / 24.0)
                                         - left)
                if left <= 0.0:
                    f = max(f, d * (1.0 + landing) + KF.LANDING_PAST)
            if f > 0.0:
                stepper.step(f * to_feed)
        out[n] = stepper.p
    return out
