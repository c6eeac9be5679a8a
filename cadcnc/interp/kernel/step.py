"""The stepper's period compiled: track, accurate step, end landing, trial cycle, commit.

Mirrors ``Stepper.step`` of cadcnc/interp/stepper.py (the reference) on flat arrays:

- ``F`` float64 / ``I`` int64: both surfaces packed by ``cadcnc.interp.compiled.pack``
  (evaluator arrays, trim grid, wrap) behind a header per surface;
- ``S`` float64 (STATE_SIZE,): the state (centre, direction, contacts c1 c2, spares n1 n2,
  the kept landing trial, counters, tolerances) and scratch;
- ``R`` (capacity, ROW): the record's rows (PathRecord layout), written at commit when
  ``n_rec`` >= 0.

Every offset into them is named in :mod:`.layout`.

Statuses are small ints (below); the Python side turns them into stop reasons and
messages. Nothing allocates; one trial costs two evaluations and a few hundred flops.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from . import trim_lookup
from .cycle_math import (
    PAPER_INVERSE_LIMIT,
    accurate_step,
    axpy,
    centre,
    correct,
    cross,
    curvature,
    dot,
    inverse,
    inverse_exact,
    norm,
    paper_inverse_ratio,
    put,
    scale,
    set_geometry,
    sub,
    tangent_coords,
    vec,
)
from .evaluators import OK as EVAL_OK
from .evaluators import d2
from .layout import (
    ACC_CYCLES,
    ACC_RATIO,
    AUTO_COMMIT,
    C1,
    C2,
    C_E,
    C_NRM,
    C_OFF,
    C_R,
    C_SING,
    C_U,
    C_W,
    CHECK_BOUNDARY,
    CS,
    CYCLES,
    D_OUT,
    DIAG,
    DP,
    END_P,
    END_UV1,
    END_UV2,
    EX1,
    EX2,
    F_TRIAL,
    G_DU,
    G_DW,
    G_FINE,
    G_NORMAL_SIGN,
    G_U0,
    G_UMIN,
    G_UPERIOD,
    G_W0,
    G_WIN_U,
    G_WIN_UP,
    G_WIN_W,
    G_WIN_WP,
    G_WMIN,
    G_WPERIOD,
    GUARD_B,
    GUARD_Q,
    H_CELLS,
    H_CELLS_NU,
    H_CELLS_NW,
    H_IARR,
    H_IARR_LEN,
    H_KIND,
    H_KU,
    H_KU_LEN,
    H_KV,
    H_KV_LEN,
    H_NU,
    H_NV,
    H_PARAMS,
    H_PARAMS_LEN,
    H_POLES,
    H_WEIGHTS,
    HAS_END,
    HAS_LAST,
    HEAD,
    K1,
    K2,
    KEPT1,
    KEPT2,
    KEPT_P,
    KEPT_T,
    LAST_K1,
    LAST_K2,
    LAST_R1,
    LAST_R2,
    MARGIN,
    MIN_STEP,
    N1,
    N2,
    P_E,
    R_COMMANDED,
    R_CONTACTS,
    R_FORMS,
    R_POINTS,
    R_RATIO,
    R_STEP,
    R_UV,
    RATIO,
    REESTIMATE,
    TOL_ACCURACY,
    TOL_DIVERGED,
    TOL_END,
    TOL_FLAT,
    TOL_SINGULAR,
    TOL_TANGENT,
    TR_OK,
    TR_T,
    TRAVELLED,
    TRIM_STATE,
    WATCH,
    WORK,
    WORK_SIZE,
    P,
    T,
)
from .trim_lookup import CELL_INSIDE, CELL_MIXED, CELL_OUTSIDE

_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
lookup = trim_lookup.lookup   # numba-compiled already (.trim_lookup)
wrap = trim_lookup.wrap

# statuses
DONE, TANGENT, CURVATURE, SINGULAR, DIVERGED, BOUNDARY, EVAL_FAIL, MOVE_UNDEFINED = range(8)
TRACK_TANGENT, END_STOP, END_LANDED, PASSED, CHECK_TRIM, MAX_CYCLES, RECORD_FULL = range(8, 15)
"""DONE: a step committed. PASSED: a trial passed every compiled rule (the caller asks the
guard, then commits). CHECK_TRIM: a spare contact's cell is MIXED (TRIM_STATE says which):
the caller classifies exactly. END_STOP / END_LANDED: at the end (no step / last step)."""

WATCH_NONE = -1.0


@_jit
def move_to(F: np.ndarray, I: np.ndarray, S: np.ndarray, s: int, o: int, u: float,
            w: float) -> int:
    """Contact.move_to: wrap, evaluate (compiled d2), refresh the contact row at o."""
    h = HEAD * s
    if F[h + G_UPERIOD] > 0.0:
        u = F[h + G_UMIN] + (u - F[h + G_UMIN]) % F[h + G_UPERIOD]
    if F[h + G_WPERIOD] > 0.0:
        w = F[h + G_WMIN] + (w - F[h + G_WMIN]) % F[h + G_WPERIOD]
    a = I[h + H_PARAMS]
    b = I[h + H_IARR]
    ku = I[h + H_KU]
    kv = I[h + H_KV]
    poles = I[h + H_POLES]
    weights = I[h + H_WEIGHTS]
    nu = I[h + H_NU]
    nv = I[h + H_NV]
    out = S[D_OUT:D_OUT + 18].reshape((6, 3))
    status = d2(I[h + H_KIND], F[a:a + I[h + H_PARAMS_LEN]], I[b:b + I[h + H_IARR_LEN]],
                F[ku:ku + I[h + H_KU_LEN]], F[kv:kv + I[h + H_KV_LEN]],
                F[poles:poles + nu * nv * 3].reshape((nu, nv, 3)),
                F[weights:weights + nu * nv].reshape((nu, nv)), u, w,
                S[WORK:WORK + WORK_SIZE], out)
    if status != EVAL_OK:
        return status
    set_geometry(S, o, F[h + G_NORMAL_SIGN], u, w, out)
    return EVAL_OK


@_jit
def trim_cell(F: np.ndarray, I: np.ndarray, s: int, u: float, w: float) -> int:
    h = HEAD * s
    if I[h + H_CELLS_NU] == 0:
        return CELL_MIXED
    g = I[h + H_CELLS]
    nu = I[h + H_CELLS_NU]
    nw = I[h + H_CELLS_NW]
    return lookup(I[g:g + nu * nw].reshape((nu, nw)), F[int(F[h + G_FINE]):], F[h + G_U0],
                  F[h + G_W0], F[h + G_DU], F[h + G_DW], nu, nw,
                  wrap(u, F[h + G_WIN_U], F[h + G_WIN_UP]),
                  wrap(w, F[h + G_WIN_W], F[h + G_WIN_WP]))


@_jit
def _fail(S: np.ndarray, status: int, label: int, a: float, b: float, margin: float) -> int:
    S[DIAG] = label
    S[DIAG + 1] = a
    S[DIAG + 2] = b
    S[MARGIN] = margin
    return status


@_jit
def _watch(S: np.ndarray, rule: int, m: float) -> None:
    if S[WATCH] == rule:
        S[MARGIN] = min(S[MARGIN], m)


@_jit
def trial(F: np.ndarray, I: np.ndarray, S: np.ndarray, f: float) -> int:
    """Stepper._try without the guard: a cycle of step f into the spares (n1, n2) and
    its checks. PASSED, CHECK_TRIM (the trim states in S[TRIM_STATE]) or a failure."""
    S[MARGIN] = math.inf
    S[F_TRIAL] = f
    t = vec(S, TR_T)
    k1 = S[K1]
    k2 = S[K2]
    ok, p_e = correct(S, C1, C2, k1, k2, axpy(f, t, vec(S, P)), S[TOL_FLAT])
    if not ok:
        return _fail(S, TANGENT, 0, 0.0, 0.0, math.nan)
    put(S, P_E, p_e)
    for side in range(2):
        o = C1 if side == 0 else C2
        if S[EX1 + side] != 0.0:
            ok, du, dw = inverse_exact(S, o, p_e)
            if not ok:
                return _fail(S, MOVE_UNDEFINED, 0, 0.0, 0.0, math.nan)
        else:
            du, dw = inverse(S, o, S[K1 + side], p_e)
        S[REESTIMATE + 2 * side] = S[o + C_U] + du
        S[REESTIMATE + 2 * side + 1] = S[o + C_W] + dw
    for side in range(2):
        o = N1 if side == 0 else N2
        status = move_to(F, I, S, side, o, S[REESTIMATE + 2 * side],
                         S[REESTIMATE + 2 * side + 1])
        if status != EVAL_OK:
            return _fail(S, EVAL_FAIL, side + 1, S[REESTIMATE + 2 * side],
                         S[REESTIMATE + 2 * side + 1], math.nan)
        m = S[o + C_SING] - S[TOL_SINGULAR]
        if m < 0.0:
            return _fail(S, SINGULAR, side + 1, S[o + C_U], S[o + C_W], m)
        _watch(S, SINGULAR, m)
        eps = norm(sub(p_e, centre(S, o)))
        if eps > S[TOL_DIVERGED]:
            return _fail(S, DIVERGED, side + 1, eps, 0.0, S[TOL_DIVERGED] - eps)
        _watch(S, DIVERGED, S[TOL_DIVERGED] - eps)
        k = curvature(S, o, t)
        if S[o + C_OFF] * k >= 1.0:
            return _fail(S, CURVATURE, side + 1, k, S[o + C_OFF] * k, 1.0 - S[o + C_OFF] * k)
        _watch(S, CURVATURE, 1.0 - S[o + C_OFF] * k)
    if not (S[WATCH] == SINGULAR or S[WATCH] == DIVERGED or S[WATCH] == CURVATURE):
        S[MARGIN] = math.nan
    if S[CHECK_BOUNDARY] == 0.0:
        return PASSED
    ask = False
    left = False
    for side in range(2):
        o = N1 if side == 0 else N2
        state = 0
        cell = trim_cell(F, I, side, S[o + C_U], S[o + C_W])
        if cell != CELL_INSIDE:   # Stepper._left_face: re-estimate one step towards p_e
            first = cell
            k = curvature(S, o, t)
            du, dw = tangent_coords(S, o, scale(sub(p_e, centre(S, o)),
                                                1.0 / (1.0 - k * S[o + C_OFF])))
            S[REESTIMATE + 2 * side] = S[o + C_U] + du
            S[REESTIMATE + 2 * side + 1] = S[o + C_W] + dw
            cell = trim_cell(F, I, side, S[o + C_U] + du, S[o + C_W] + dw)
            if first == CELL_MIXED:
                state = 0 if cell == CELL_INSIDE else 2   # inside: not left, whatever q is
            else:
                state = 1 if cell == CELL_OUTSIDE else (2 if cell == CELL_MIXED else 0)
        S[TRIM_STATE + side] = state
        ask = ask or state == 2
        left = left or state == 1
    if ask:
        return CHECK_TRIM
    if left:
        return _fail(S, BOUNDARY, 0, 0.0, 0.0, math.nan)
    return PASSED


@_jit
def track(S: np.ndarray) -> int:
    """cycle.track at the current contacts into S[TR_T], S[K1], ...; 0 or a failure."""
    S[TR_OK] = 0.0
    m = cross(vec(S, C1 + C_NRM), vec(S, C2 + C_NRM))
    s = norm(m)
    if s < S[TOL_TANGENT]:
        return _fail(S, TRACK_TANGENT, 0, s, 0.0, math.nan)
    if dot(m, vec(S, T)) < 0.0:
        s = -s
    t = scale(m, 1.0 / s)
    k1 = curvature(S, C1, t)
    k2 = curvature(S, C2, t)
    for side in range(2):
        o = C1 if side == 0 else C2
        k = k1 if side == 0 else k2
        if S[o + C_OFF] * k >= 1.0:
            return _fail(S, CURVATURE, side + 1, k, S[o + C_OFF] * k, 1.0 - S[o + C_OFF] * k)
    put(S, TR_T, t)
    S[K1] = k1
    S[K2] = k2
    S[EX1] = 1.0 if paper_inverse_ratio(S, C1, k1) > PAPER_INVERSE_LIMIT else 0.0
    S[EX2] = 1.0 if paper_inverse_ratio(S, C2, k2) > PAPER_INVERSE_LIMIT else 0.0
    S[TR_OK] = 1.0
    return DONE


@_jit
def accurate(S: np.ndarray, f_cmd: float) -> float:
    """Stepper._accurate: the commanded step shortened for accuracy; sets S[RATIO]."""
    slope1 = 0.0
    slope2 = 0.0
    if S[HAS_LAST] != 0.0:
        d = norm(sub(vec(S, C1 + C_R), vec(S, LAST_R1)))
        slope1 = abs(S[K1] - S[LAST_K1]) / d if d > 0.0 else 0.0
        d = norm(sub(vec(S, C2 + C_R), vec(S, LAST_R2)))
        slope2 = abs(S[K2] - S[LAST_K2]) / d if d > 0.0 else 0.0
    f = accurate_step(S, vec(S, P), C1, C2, vec(S, TR_T), S[K1], S[K2], f_cmd,
                      S[TOL_ACCURACY], slope1, slope2)
    if f < f_cmd:
        f = max(f, min(S[MIN_STEP], f_cmd))
        S[RATIO] = f / f_cmd
    else:
        S[RATIO] = 1.0
    return f


@_jit
def _copy(S: np.ndarray, dst: int, src: int, n: int) -> None:
    for i in range(n):
        S[dst + i] = S[src + i]


@_jit
def _swap(S: np.ndarray, a: int, b: int) -> None:
    for i in range(CS):
        x = S[a + i]
        S[a + i] = S[b + i]
        S[b + i] = x


@_jit
def keep(S: np.ndarray) -> None:
    """Save the passed trial (spares, p_e, t) for a landing's commit."""
    _copy(S, KEPT1, N1, CS)
    _copy(S, KEPT2, N2, CS)
    _copy(S, KEPT_P, P_E, 3)
    _copy(S, KEPT_T, TR_T, 3)


@_jit
def commit(S: np.ndarray, R: np.ndarray, n_rec: int, p_e: tuple, t: tuple, f: float) -> None:
    """Stepper._commit: the spares become the contacts; one record row when n_rec >= 0."""
    dp = sub(p_e, vec(S, P))
    step = norm(dp)
    if S[TR_OK] != 0.0:
        S[LAST_K1] = S[K1]
        S[LAST_K2] = S[K2]
        _copy(S, LAST_R1, C1 + C_R, 3)
        _copy(S, LAST_R2, C2 + C_R, 3)
        S[HAS_LAST] = 1.0
    put(S, P, p_e)
    put(S, T, t)
    put(S, DP, dp)
    _swap(S, C1, N1)
    _swap(S, C2, N2)
    S[CYCLES] += 1.0
    S[TRAVELLED] += step
    if S[RATIO] < 1.0:
        S[ACC_CYCLES] += 1.0
        S[ACC_RATIO] = min(S[ACC_RATIO], S[RATIO])
    if n_rec >= 0:
        write_row(S, R, n_rec, f, step)


@_jit
def commit_kept(S: np.ndarray, R: np.ndarray, n_rec: int, f: float) -> None:
    _copy(S, N1, KEPT1, CS)
    _copy(S, N2, KEPT2, CS)
    commit(S, R, n_rec, vec(S, KEPT_P), vec(S, KEPT_T), f)


@_jit
def write_row(S: np.ndarray, R: np.ndarray, n: int, f: float, step: float) -> None:
    """PathRecord.add from the state: the columns of record.FIELDS in order."""
    _row(S, R, n, R_POINTS, P, 3)
    R[n, R_UV] = S[C1 + C_U]
    R[n, R_UV + 1] = S[C1 + C_W]
    R[n, R_UV + 2] = S[C2 + C_U]
    R[n, R_UV + 3] = S[C2 + C_W]
    col = R_CONTACTS
    for field in range(4):           # contacts, ru, rw, normals: 3 floats per surface
        _row(S, R, n, col, C1 + C_R + 3 * field, 3)
        _row(S, R, n, col + 3, C2 + C_R + 3 * field, 3)
        col += 6
    _row(S, R, n, R_FORMS, C1 + C_E, 6)   # forms E F G L M N
    _row(S, R, n, R_FORMS + 6, C2 + C_E, 6)
    R[n, R_COMMANDED] = f
    R[n, R_STEP] = step
    R[n, R_RATIO] = S[RATIO]


@_jit
def _row(S: np.ndarray, R: np.ndarray, n: int, col: int, o: int, k: int) -> None:
    for i in range(k):
        R[n, col + i] = S[o + i]


@_jit
def begin(F: np.ndarray, I: np.ndarray, S: np.ndarray, R: np.ndarray, n_rec: int,
          f_cmd: float) -> int:
    """Stepper.step up to the trial: track, accurate step, landing on the end. Returns
    DONE (go on with trial(S[F_TRIAL])), END_STOP, END_LANDED or the track's failure."""
    S[RATIO] = 1.0
    failure = track(S)
    f = f_cmd if S[TR_OK] == 0.0 else accurate(S, f_cmd)
    S[F_TRIAL] = f
    if S[HAS_END] != 0.0 and S[TRAVELLED] >= 2.0 * max(f, S[TOL_END]):   # see stepper
        d = sub(vec(S, END_P), vec(S, P))
        dist = norm(d)
        if dist <= S[TOL_END]:
            return END_STOP
        if not (dist > f or dot(d, vec(S, T)) <= 0.0):
            status = move_to(F, I, S, 0, N1, S[END_UV1], S[END_UV1 + 1])
            status = max(status, move_to(F, I, S, 1, N2, S[END_UV2], S[END_UV2 + 1]))
            if status != EVAL_OK:
                return _fail(S, EVAL_FAIL, 0, 0.0, 0.0, math.nan)
            commit(S, R, n_rec, vec(S, END_P), vec(S, T), dist)
            return END_LANDED
    return failure


@_jit
def step(F: np.ndarray, I: np.ndarray, S: np.ndarray, R: np.ndarray, n_rec: int,
         f_cmd: float) -> int:
    """One period: DONE when committed (S[AUTO_COMMIT] set: no guard; or the trial centre
    within the guard's budget), else the status
    the caller finishes (PASSED, CHECK_TRIM, a failure to land on, END_*)."""
    status = begin(F, I, S, R, n_rec, f_cmd)
    if status != DONE:
        return status
    S[WATCH] = WATCH_NONE
    status = trial(F, I, S, S[F_TRIAL])
    if status == PASSED and (S[AUTO_COMMIT] != 0.0 or within_budget(S)):
        commit(S, R, n_rec, vec(S, P_E), vec(S, TR_T), S[F_TRIAL])
        return DONE
    return status


@_jit
def within_budget(S: np.ndarray) -> bool:
    """Whether the trial centre lies within the guard's budget (S[GUARD_B] mm of the centre
    S[GUARD_Q] where the guard gave it): known clear, no need to ask the guard."""
    d = 0.0
    for k in range(3):
        d += (S[P_E + k] - S[GUARD_Q + k]) ** 2
    return math.sqrt(d) < S[GUARD_B]


@_jit
def commit_trial(S: np.ndarray, R: np.ndarray, n_rec: int) -> None:
    """Commit the trial that just passed (after the caller's exact checks and guard)."""
    commit(S, R, n_rec, vec(S, P_E), vec(S, TR_T), S[F_TRIAL])


@_jit
def state_margin(S: np.ndarray, rule: int) -> float:
    """Stepper._state_margin for SINGULAR, DIVERGED, CURVATURE at the current point."""
    if rule == SINGULAR:
        return min(S[C1 + C_SING], S[C2 + C_SING]) - S[TOL_SINGULAR]
    if rule == DIVERGED:
        p = vec(S, P)
        return S[TOL_DIVERGED] - max(norm(sub(p, centre(S, C1))), norm(sub(p, centre(S, C2))))
    if rule == CURVATURE:
        t = vec(S, TR_T)
        return 1.0 - max(S[C1 + C_OFF] * curvature(S, C1, t), S[C2 + C_OFF] * curvature(S, C2, t))
    return math.nan

