"""The compiled stepper's entry points: the one function Python calls, and the loop.

``entry`` dispatches every operation the Python side needs (kernel/step.py does the work):
numba loads one cached library for it at start-up instead of one per function (about 0.3 s
each). ``run`` is the period loop of ``Stepper.run`` between events.
"""

from __future__ import annotations

import numba
import numpy as np

from .layout import ARG_U, ARG_W, C1, C2, CYCLES, MARGIN
from .step import (
    DONE,
    MAX_CYCLES,
    RECORD_FULL,
    commit_kept,
    commit_trial,
    keep,
    move_to,
    state_margin,
    step,
    trial,
    write_row,
)

_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)


@_jit
def run(F: np.ndarray, I: np.ndarray, S: np.ndarray, R: np.ndarray, n_rec: int,
        f_cmd: float, max_cycles: int) -> tuple:
    """Steps until one needs the caller: (status, rows recorded). MAX_CYCLES at the
    limit, RECORD_FULL when R has no room for the next row."""
    while True:
        if S[CYCLES] >= max_cycles:
            return MAX_CYCLES, n_rec
        if n_rec >= R.shape[0]:
            return RECORD_FULL, n_rec
        status = step(F, I, S, R, n_rec, f_cmd)
        if status != DONE:
            return status, n_rec
        if n_rec >= 0:
            n_rec += 1


OP_STEP, OP_RUN, OP_TRIAL, OP_KEEP, OP_COMMIT_TRIAL, OP_COMMIT_KEPT = range(6)
OP_MOVE_TO, OP_FIRST_ROW, OP_STATE_MARGIN = 6, 7, 8


@_jit
def entry(op: int, F: np.ndarray, I: np.ndarray, S: np.ndarray, R: np.ndarray, n_rec: int,
          x: float, k: int) -> tuple:
    """The one function Python calls (one cached library to load at start-up, not one per
    function): (status, rows recorded, value) of operation ``op`` with the float ``x``
    (a step, mm) and the int ``k`` (cycle limit, surface side or rule)."""
    if op == OP_STEP:
        return step(F, I, S, R, n_rec, x), n_rec, 0.0
    if op == OP_RUN:
        status, n = run(F, I, S, R, n_rec, x, k)
        return status, n, 0.0
    if op == OP_TRIAL:
        return trial(F, I, S, x), n_rec, S[MARGIN]
    if op == OP_KEEP:
        keep(S)
    elif op == OP_COMMIT_TRIAL:
        commit_trial(S, R, n_rec)
    elif op == OP_COMMIT_KEPT:
        commit_kept(S, R, n_rec, x)
    elif op == OP_MOVE_TO:
        return move_to(F, I, S, k, C1 if k == 0 else C2, S[ARG_U], S[ARG_W]), n_rec, 0.0
    elif op == OP_FIRST_ROW:
        write_row(S, R, n_rec, 0.0, 0.0)
    elif op == OP_STATE_MARGIN:
        return DONE, n_rec, state_margin(S, k)
    return DONE, n_rec, 0.0
