"""Where the compiled stepper keeps what: the offsets of its flat arrays, named once.

``cadcnc.interp.compiled`` writes these arrays (``pack``, ``CompiledStepper``) and the
kernel (``step``, ``entry``, ``follow``) reads them; both name every slot from here.
numba treats these module-level ints as compile-time constants: naming costs nothing.

- ``F`` (float64) / ``I`` (int64): the surfaces' packed data. Surface s (0 or 1) has a
  header of ``HEAD`` slots at ``HEAD * s`` in both: the ints ``H_*`` (evaluator kind, and
  each evaluator array as an offset into F or I and a length; the trim grid's cell
  codes), the floats ``G_*`` (the trim grid's origin and cell size, its wrap window,
  the surface's wrap ranges and periods, the normal's sign, the offset of the grid's
  MIXED cells' segments). The arrays follow the ``HEADERS`` slots of both headers.
- ``S`` (float64, ``STATE_SIZE``): the state. ``STATE`` lists each field's offset and
  width; a contact block (``C1`` ...) holds ``CS`` floats laid out by the ``C_*``
  offsets.
- ``R`` (rows, ``ROW``): the record, the columns of ``cadcnc.interp.record.FIELDS``.

Changing an offset here recompiles the kernel: its cached code is stamped with a hash of
every file of this package (``cadcnc.interp.kernel``).
"""

from __future__ import annotations

# -- F and I: one header per surface ----------------------------------------------------
HEAD = 16
"""Slots of one surface's header in F and in I."""
HEADERS = 2 * HEAD
"""Slots of both headers: the packed arrays start here in F and in I."""
H_KIND = 0                     # evaluator kind (evaluators.d2)
H_PARAMS, H_PARAMS_LEN = 1, 2  # F: the evaluator's float parameters
H_IARR, H_IARR_LEN = 3, 4      # I: its int parameters
H_KU, H_KU_LEN = 5, 6          # F: u knots
H_KV, H_KV_LEN = 7, 8          # F: v knots
H_POLES = 9                    # F: poles (nu, nv, 3)
H_NU, H_NV = 10, 11            # the poles' grid
H_WEIGHTS = 12                 # F: weights (nu, nv)
H_CELLS, H_CELLS_NU, H_CELLS_NW = 13, 14, 15   # I: the trim grid's cell codes (nu, nw)
G_U0, G_W0, G_DU, G_DW = 0, 1, 2, 3            # the trim grid's origin and cell size
G_WIN_U, G_WIN_UP, G_WIN_W, G_WIN_WP = 4, 5, 6, 7  # its window: u start, period, w ...
G_UMIN, G_UPERIOD, G_WMIN, G_WPERIOD = 8, 9, 10, 11  # the surface's wrap (period 0: none)
G_NORMAL_SIGN = 12             # +1 or -1: the normal out of the material
G_FINE = 13                    # offset in F of the MIXED cells' segments
G_USED = 14                    # float header slots in use

# -- S: a contact block ------------------------------------------------------------------
C_U, C_W, C_R, C_RU, C_RW, C_NRM = 0, 1, 2, 5, 8, 11
C_E, C_F, C_G, C_L, C_M, C_N, C_SING, C_OFF = 14, 15, 16, 17, 18, 19, 20, 21
CS = 24
"""Floats of a contact block (22 used)."""

# -- S: the state ------------------------------------------------------------------------
P, T, TR_T, K1, K2, EX1, EX2, TR_OK = 0, 3, 6, 9, 10, 11, 12, 13
LAST_K1, LAST_K2, LAST_R1, LAST_R2, HAS_LAST = 14, 15, 16, 19, 22
P_E, RATIO, F_TRIAL, MARGIN, DIAG, DP = 23, 27, 28, 29, 30, 33   # DIAG: label, a, b
CYCLES, TRAVELLED, ACC_CYCLES, ACC_RATIO = 36, 37, 38, 39
END_P, END_UV1, END_UV2, HAS_END, CLOSED = 40, 43, 45, 47, 48
TOL_TANGENT, TOL_FLAT, TOL_SINGULAR, TOL_DIVERGED, TOL_ACCURACY = 49, 50, 51, 52, 53
TOL_END, MIN_STEP, CHECK_BOUNDARY, WATCH, AUTO_COMMIT = 54, 55, 56, 57, 58
TRIM_STATE, REESTIMATE = 60, 62          # 2 states (0 in, 1 out, 2 ask), 2 x (u, w)
GUARD_Q, GUARD_B = 66, 69                # the guard's budget: clear within B of Q
ARG_U, ARG_W = 70, 71                    # OP_MOVE_TO's parameters (entry)
C1, C2, N1, N2, KEPT1, KEPT2, KEPT_P, KEPT_T = 80, 104, 128, 152, 176, 200, 224, 227
D_OUT, WORK = 240, 260                   # an evaluation's (6, 3) output; its scratch
WORK_SIZE = 2048
STATE_SIZE = WORK + WORK_SIZE

STATE = {
    "P": (P, 3), "T": (T, 3), "TR_T": (TR_T, 3), "K1": (K1, 1), "K2": (K2, 1),
    "EX1": (EX1, 1), "EX2": (EX2, 1), "TR_OK": (TR_OK, 1), "LAST_K1": (LAST_K1, 1),
    "LAST_K2": (LAST_K2, 1), "LAST_R1": (LAST_R1, 3), "LAST_R2": (LAST_R2, 3),
    "HAS_LAST": (HAS_LAST, 1), "P_E": (P_E, 3), "RATIO": (RATIO, 1),
    "F_TRIAL": (F_TRIAL, 1), "MARGIN": (MARGIN, 1), "DIAG": (DIAG, 3), "DP": (DP, 3),
    "CYCLES": (CYCLES, 1), "TRAVELLED": (TRAVELLED, 1), "ACC_CYCLES": (ACC_CYCLES, 1),
    "ACC_RATIO": (ACC_RATIO, 1), "END_P": (END_P, 3), "END_UV1": (END_UV1, 2),
    "END_UV2": (END_UV2, 2), "HAS_END": (HAS_END, 1), "CLOSED": (CLOSED, 1),
    "TOL_TANGENT": (TOL_TANGENT, 1), "TOL_FLAT": (TOL_FLAT, 1),
    "TOL_SINGULAR": (TOL_SINGULAR, 1), "TOL_DIVERGED": (TOL_DIVERGED, 1),
    "TOL_ACCURACY": (TOL_ACCURACY, 1), "TOL_END": (TOL_END, 1), "MIN_STEP": (MIN_STEP, 1),
    "CHECK_BOUNDARY": (CHECK_BOUNDARY, 1), "WATCH": (WATCH, 1),
    "AUTO_COMMIT": (AUTO_COMMIT, 1), "TRIM_STATE": (TRIM_STATE, 2),
    "REESTIMATE": (REESTIMATE, 4), "GUARD_Q": (GUARD_Q, 3), "GUARD_B": (GUARD_B, 1),
    "ARG_U": (ARG_U, 1), "ARG_W": (ARG_W, 1), "C1": (C1, CS), "C2": (C2, CS),
    "N1": (N1, CS), "N2": (N2, CS), "KEPT1": (KEPT1, CS), "KEPT2": (KEPT2, CS),
    "KEPT_P": (KEPT_P, 3), "KEPT_T": (KEPT_T, 3), "D_OUT": (D_OUT, 18),
    "WORK": (WORK, WORK_SIZE),
}
"""name -> (offset, width) of every field of S (read by the layout's test)."""

# -- R: the record's columns (record.FIELDS) ---------------------------------------------
R_POINTS, R_UV, R_CONTACTS, R_FORMS = 0, 3, 7, 31
R_COMMANDED, R_STEP, R_RATIO = 43, 44, 45
ROW = 46
