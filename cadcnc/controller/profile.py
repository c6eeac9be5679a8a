"""A run's planned motion s(t) (:class:`Profile`): what :func:`.run_plan.plan_run` returns
and the stream reads, a position per servo period. Times s, lengths mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from . import topp


@dataclass
class Profile:
    """One run's planned motion s(t), t from 0 (at rest at s = 0) to ``duration`` (at
    rest at s = L): the profile on ``t``, ``s``, ``v``, ``a`` (the interval k from t[k]
    has acceleration a[k]) and ``S`` = its time integral, averaged over ``window`` s.
    ``measured``: planned with its limits where they are, its averaged motion measured
    (:func:`.run_plan.plan_run`), not held over the window's reach."""

    t: np.ndarray
    s: np.ndarray
    v: np.ndarray
    a: np.ndarray
    S: np.ndarray
    window: float
    measured: bool = False

    @property
    def length(self) -> float:
        return float(self.s[-1])

    @property
    def duration(self) -> float:
        return float(self.t[-1]) + self.window

    def position(self, tau: np.ndarray) -> np.ndarray:
        """s (mm) at local times ``tau`` (s), clipped to [0, L]."""
        tau = np.ascontiguousarray(tau, dtype=float)
        out = np.empty(tau.shape)
        _positions(self.t, self.s, self.v, self.a, self.S, self.window, tau.ravel(),
                   out.ravel())
        return out


@njit(cache=True, error_model="numpy")
def _positions(t, s, v, a, S, window: float, tau, out) -> None:
    """Profile.position into ``out``: s(t) averaged over ``window`` (or s(t) if 0),
    ``tau`` non-decreasing or not (sorted sweeps are linear)."""
    if len(tau) and (tau[1:] >= tau[:-1]).all():
        topp.averaged_sweep(t, s, v, a, S, window, tau, out)
        return
    for i in range(len(tau)):
        out[i] = topp.averaged(t, s, v, a, S, window, tau[i], 0)
