"""The stepper on the compiled kernel: Stepper's rules, with the period's work in numba.

:func:`new_stepper` builds a :class:`CompiledStepper` when both surfaces offer compiled
data (``surface.kernel`` = (surface data, trim grid), see cadcnc.geometry.face_surface)
and ``compiled`` is True, else the reference :class:`Stepper`. Each period is one call
of ``kernel.step.step`` (track, accurate step, end landing, trial cycle on the compiled
evaluators, O(1) trim check, commit, record row); Python is entered only for what the
kernel leaves to it: an exact trim classification where a contact's grid cell is MIXED,
the guard, a landing (the same ``landing.land`` as the reference) and the messages. ``run`` loops in the kernel
(``kernel.entry.run``) between such events, ``follow`` likewise with a per-period step
plan (``kernel.follow``). The plain-Python Stepper stays the reference:
tests compare the two paths point for point. No OCCT here.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.errors import GeometryError
from ..core.job import MIN_STEP as JOB_MIN_STEP
from ..core.job import check_number, check_step
from ..core.progress import travelled_text
from ..core.tolerances import DEFAULT
from ..core.trim_labels import OUTSIDE
from .cycle import (
    BOUNDARY,
    CLOSED,
    COLLISION,
    CORRECTION_SINGULAR,
    CURVATURE,
    DIVERGED,
    END,
    MAX_CYCLES,
    MOVE_UNDEFINED,
    SINGULAR,
    TANGENT,
    Contact,
    boundary_detail,
    curvature_detail,
    diverged_detail,
    singular_detail,
    tangent_detail,
)
from .kernel import entry as E
from .kernel import follow as KF
from .kernel import layout as L
from .kernel import step as K
from .record import ROW, PathRecord
from .stepper import Stepper, Tangency
from .vec3 import Vec

_CODES = {SINGULAR: K.SINGULAR, DIVERGED: K.DIVERGED, CURVATURE: K.CURVATURE}
_NO_ROWS = np.zeros((1, ROW))


def kernel_data(surface) -> tuple | None:
    """The surface's (surface data, trim grid) when it has them, else None."""
    return getattr(surface, "kernel", None)


def pack(surfaces, grids) -> tuple[np.ndarray, np.ndarray]:
    """F (float64) and I (int64) holding both surfaces' evaluator arrays, trim grids and
    wrap data in the layout of kernel/layout.py."""
    floats, ints = [np.zeros(L.HEADERS)], [np.zeros(L.HEADERS, dtype=np.int64)]
    nf, ni = L.HEADERS, L.HEADERS
    for s, (surface, (data, grid)) in enumerate(zip(surfaces, grids)):
        kind, params, iarr, ku, kv, poles, weights = data.args
        h = L.HEAD * s
        head = ints[0]
        head[h + L.H_KIND] = kind
        for slot, arr in ((L.H_PARAMS, params), (L.H_KU, ku), (L.H_KV, kv),
                          (L.H_POLES, poles), (L.H_WEIGHTS, weights)):
            head[h + slot] = nf
            floats.append(np.ascontiguousarray(arr, dtype=np.float64).ravel())
            nf += floats[-1].size
        head[h + L.H_PARAMS_LEN], head[h + L.H_KU_LEN] = len(params), len(ku)
        head[h + L.H_KV_LEN] = len(kv)
        head[h + L.H_NU], head[h + L.H_NV] = poles.shape[0], poles.shape[1]
        head[h + L.H_IARR], head[h + L.H_IARR_LEN] = ni, len(iarr)
        ints.append(np.asarray(iarr, dtype=np.int64))
        ni += len(iarr)
        codes, fine, u0, w0, du, dw, nu, nw = grid.kernel_args
        head[h + L.H_CELLS], head[h + L.H_CELLS_NU], head[h + L.H_CELLS_NW] = ni, nu, nw
        ints.append(codes.astype(np.int64, copy=False).ravel())
        ni += nu * nw
        floats.append(np.asarray(fine, dtype=np.float64))  # MIXED cells' segments
        (umin, _), (wmin, _) = surface.u_range, surface.w_range
        floats[0][h + L.G_U0:h + L.G_USED] = (
            u0, w0, du, dw, *grid.window, umin, surface.u_period or 0.0, wmin,
            surface.w_period or 0.0, surface.normal_sign, nf)
        nf += len(fine)
    return np.concatenate(floats), np.concatenate(ints)


def new_stepper(s1, s2, offsets: tuple[float, float], start: Tangency, *, compiled: bool = True,
                **kwargs) -> Stepper:
    """The stepper of two surfaces (the arguments of :class:`Stepper`): a
    :class:`CompiledStepper` when ``compiled`` and both surfaces have compiled data, else
    the plain-Python reference (``compiled=False``: always; the two agree point for
    point)."""
    if compiled and kernel_data(s1) and kernel_data(s2):
        return CompiledStepper(s1, s2, offsets, start, **kwargs)
    return Stepper(s1, s2, offsets, start, **kwargs)


class CompiledStepper(Stepper):
    """:class:`Stepper` with the per-period work compiled; the same attributes, steps and
    stop rules (its state lives in the kernel's array ``S``)."""

    def __init__(self, s1, s2, offsets: tuple[float, float], start: Tangency, *,
                 feed: float, period: float, direction: Vec, end: Tangency | None = None,
                 closed: bool = False, tol=None, max_cycles: int = 1_000_000,
                 record: bool = True, check_boundary: bool = True, guard=None):
        tol = DEFAULT if tol is None else tol
        self.tol, self.surfaces = tol, (s1, s2)
        self.period = check_number("period", period, "s")
        self.feed = self._check_feed(feed)
        check_step(self.feed, self.period)
        self._grids = (kernel_data(s1)[1], kernel_data(s2)[1])
        self.F, self.I = pack((s1, s2), (kernel_data(s1), kernel_data(s2)))
        self.S = S = np.zeros(L.STATE_SIZE)
        self.record = PathRecord() if record else None
        S[L.P:L.P + 3] = start.p
        d = math.sqrt(sum(float(x) ** 2 for x in direction))
        S[L.T:L.T + 3] = [float(x) / d for x in direction] if d > 0 else 0.0
        self.end = Tangency(start.p, start.uv1, start.uv2) if closed else end
        if self.end is not None:
            S[L.END_P:L.END_P + 3] = self.end.p
            S[L.END_UV1:L.END_UV1 + 2] = self.end.uv1
            S[L.END_UV2:L.END_UV2 + 2] = self.end.uv2
            S[L.HAS_END] = 1.0
        S[L.TOL_TANGENT:L.TOL_END + 1] = (tol.tangent_sin, tol.flat_curvature,
                                         tol.near_singular, tol.diverged, tol.accuracy,
                                         tol.end_reached)
        S[L.MIN_STEP], S[L.CHECK_BOUNDARY] = JOB_MIN_STEP, float(check_boundary)
        S[L.AUTO_COMMIT], S[L.ACC_RATIO], S[L.RATIO] = float(guard is None), 1.0, 1.0
        for side, o in enumerate((L.C1, L.C2)):
            for block in (o, o + L.N1 - L.C1, o + L.KEPT1 - L.C1):
                S[block + L.C_OFF] = float(offsets[side])
            uv = (start.uv1, start.uv2)[side]
            S[L.ARG_U], S[L.ARG_W] = uv
            if self._call(E.OP_MOVE_TO, -1, 0.0, side)[0] != 0:
                raise GeometryError(f"surface {side + 1}: the compiled evaluator cannot "
                                    f"evaluate the start contact ({uv[0]:.6g}, {uv[1]:.6g})")
        self.closed, self.max_cycles, self.check_boundary = closed, max_cycles, check_boundary
        self.guard, self.stop_reason, self.stop_detail = guard, None, ""
        self._watch, self._margin, self.landing_trials = None, math.nan, 0
        if self.record is not None:
            self._call(E.OP_FIRST_ROW, 0)
            self.record.set_length(1)

    # -- state read from the kernel's array ------------------------------------------------
    p = property(lambda self: tuple(self.S[L.P:L.P + 3].tolist()))
    t = property(lambda self: tuple(self.S[L.T:L.T + 3].tolist()))
    cycles = property(lambda self: int(self.S[L.CYCLES]))
    travelled = property(lambda self: float(self.S[L.TRAVELLED]))
    accuracy_cycles = property(lambda self: int(self.S[L.ACC_CYCLES]))
    accuracy_ratio = property(lambda self: float(self.S[L.ACC_RATIO]))
    c1 = property(lambda self: self._contact(0))
    c2 = property(lambda self: self._contact(1))

    def _contact(self, side: int) -> Contact:
        """A snapshot of contact 1 or 2 as the reference's Contact (for inspection)."""
        o, S = (L.C1, L.C2)[side], self.S
        c = object.__new__(Contact)
        c.surface, c.offset = self.surfaces[side], S[o + L.C_OFF]
        c.u, c.w = S[o + L.C_U], S[o + L.C_W]
        c.r, c.ru, c.rw, c.n = (tuple(S[o + k:o + k + 3].tolist())
                                for k in (L.C_R, L.C_RU, L.C_RW, L.C_NRM))
        c.E, c.F, c.G, c.L, c.M, c.N = S[o + L.C_E:o + L.C_N + 1].tolist()
        c.singularity = float(S[o + L.C_SING])
        return c

    def _call(self, op: int, n: int, x: float = 0.0, k: int = 0) -> tuple:
        """One kernel operation (kernel/step.py ``entry``)."""
        return E.entry(op, self.F, self.I, self.S, self._rows(), n, x, k)

    def _row(self) -> int:
        """The record row the next commit writes (-1: record off), growing it if full."""
        rec = self.record
        if rec is None:
            return -1
        if len(rec) == len(rec.rows):
            rec.grow()
        return len(rec)

    def _rows(self) -> np.ndarray:
        return _NO_ROWS if self.record is None else self.record.rows

    def _committed(self, n: int) -> Vec:
        if n >= 0:
            self.record.set_length(n + 1)
        return tuple(self.S[L.DP:L.DP + 3].tolist())

    def step(self, feed: float | None = None) -> Vec | None:
        """As :meth:`Stepper.step`: the next period's dp_K (mm), None once stopped."""
        if not self._may_step(feed):
            return None
        n = self._row()
        status = E.entry(E.OP_STEP, self.F, self.I, self.S, self._rows(), n,
                         self.step_length, 0)[0]
        if status == K.DONE:
            return self._committed(n)
        return self._finish(status, n)

    def run(self, progress=None, every: int = 10000) -> "Stepper":
        """As :meth:`Stepper.run`, with the loop in the kernel between events."""
        reported = -1
        while self.stop_reason is None:
            limit = self.max_cycles
            if progress is not None:
                limit = min(limit, (self.cycles // every + 1) * every)
            n = self._row()
            status, n, _ = self._call(E.OP_RUN, n, self.step_length, limit)
            if self.record is not None:
                self.record.set_length(n)
            if status == K.MAX_CYCLES:
                if self.cycles >= self.max_cycles:
                    self._stop(MAX_CYCLES, f"cycle limit {self.max_cycles} reached")
            elif status != K.RECORD_FULL and self._finish(status, self._row()) is None:
                continue
            cycles = self.cycles
            if progress is not None and cycles % every == 0 and cycles != reported:
                reported = cycles
                progress(cycles, 0, travelled_text(self.travelled))
        return self

    def follow(self, plan: np.ndarray, args: np.ndarray) -> np.ndarray:
        """(rows, 3) the centre after each period of ``plan`` (``kernel.follow``), the loop
        in the kernel between events; rows after a stop hold the last position."""
        plan = np.ascontiguousarray(plan, dtype=np.float64)
        out = np.empty((len(plan), 3))
        n = 0
        while n < len(plan):
            if self.stop_reason is not None:
                out[n:] = self.S[L.P:L.P + 3]
                break
            status, n, rec = KF.follow(self.F, self.I, self.S, self._rows(), self._row(),
                                       plan, args, out, n, self.max_cycles)
            if self.record is not None:
                self.record.set_length(rec)
            if status == K.DONE:
                break
            if status == K.RECORD_FULL:
                continue
            if status == K.MAX_CYCLES:
                self._stop(MAX_CYCLES, f"cycle limit {self.max_cycles} reached")
            else:
                self._finish(status, self._row())
            out[n] = self.S[L.P:L.P + 3]
            n += 1
        return out

    def _finish(self, status: int, n: int) -> Vec | None:
        """Complete a period the kernel handed back: end, a stop, the exact checks."""
        S = self.S
        if status in (K.END_STOP, K.END_LANDED):
            done = "closed intersection completed" if self.closed else "end point reached"
            self._stop(CLOSED if self.closed else END,
                       done if status == K.END_LANDED else "end point reached")
            return self._committed(n) if status == K.END_LANDED else None
        if S[L.TR_OK] == 0.0:
            reason, detail = self._failure(status)
            self._stop(reason, detail + " (no step possible from the current point)")
            return None
        self._margin = S[L.MARGIN]
        failure = self._resolve(status)
        if failure is None:
            self._call(E.OP_COMMIT_TRIAL, n)
            return self._committed(n)
        return self._land_on_limit(float(S[L.F_TRIAL]), failure)

    def _failure(self, status: int) -> tuple[str, str]:
        S = self.S
        label, a, b = f"surface {int(S[L.DIAG])}", S[L.DIAG + 1], S[L.DIAG + 2]
        if status == K.TRACK_TANGENT:
            return TANGENT, tangent_detail(a, self.tol)
        if status == K.TANGENT:
            return TANGENT, CORRECTION_SINGULAR
        if status == K.MOVE_UNDEFINED:
            return CURVATURE, MOVE_UNDEFINED
        if status == K.CURVATURE:
            return CURVATURE, curvature_detail(label, a, b)
        if status == K.SINGULAR:
            return SINGULAR, singular_detail(label, a, b)
        if status == K.DIVERGED:
            return self._curvature_limit(a) or (DIVERGED, diverged_detail(label, a, self.tol))
        if status == K.BOUNDARY:
            return BOUNDARY, boundary_detail(self._left())
        return SINGULAR, (f"{label}: the compiled evaluator cannot evaluate "
                          f"(u={a:.6g}, w={b:.6g}) (offset surface with a singular basis)")

    def _left(self) -> str:
        """Stepper._left_face's names from the kernel's trim states; state 2 (MIXED cell)
        is classified exactly here: left if the contact and its re-estimate are outside."""
        S, names = self.S, []
        for side in range(2):
            state = S[L.TRIM_STATE + side]
            if state == 2:
                o = (L.N1, L.N2)[side]
                grid = self._grids[side]
                again = S[L.REESTIMATE + 2 * side], S[L.REESTIMATE + 2 * side + 1]
                state = float(grid.classify(S[o + L.C_U], S[o + L.C_W]) == OUTSIDE
                              and grid.classify(*again) == OUTSIDE)
            if state == 1:
                names.append(f"surface {side + 1}")
        return " and ".join(names)

    def _resolve(self, status: int) -> tuple[str, str] | None:
        """The rest of Stepper._try after the kernel's trial: exact trim checks, guard."""
        if status == K.CHECK_TRIM:
            left = self._left()
            if left:
                return BOUNDARY, boundary_detail(left)
        elif status != K.PASSED:
            return self._failure(status)
        if self.guard is not None:
            clearance, detail = self.guard.margin(tuple(self.S[L.P_E:L.P_E + 3].tolist()))
            if self._watch == COLLISION or clearance < 0.0:
                self._margin = clearance
            if clearance < 0.0:
                return COLLISION, detail
            budget = getattr(self.guard, "budget", None)
            if budget is not None:  # clear within this distance: the kernel commits alone
                S = self.S
                S[L.GUARD_Q:L.GUARD_Q + 3] = S[L.P_E:L.P_E + 3]
                S[L.GUARD_B] = float(budget(tuple(S[L.P_E:L.P_E + 3].tolist())))
        return None

    # -- the landing's primitives (Stepper._land_on_limit drives them) ----------------------
    def _try(self, f: float) -> tuple[str, str] | None:
        self.S[L.WATCH] = _CODES.get(self._watch, K.WATCH_NONE)
        status, _, self._margin = self._call(E.OP_TRIAL, -1, f)
        return self._resolve(status)

    def _keep_trial(self) -> None:
        self._call(E.OP_KEEP, -1)

    def _commit_kept(self, f: float) -> Vec:
        n = self._row()
        self._call(E.OP_COMMIT_KEPT, n, f)
        return self._committed(n)

    def _state_margin(self, rule: str) -> float:
        if rule == COLLISION:
            return self.guard.margin(self.p)[0]
        return self._call(E.OP_STATE_MARGIN, -1, 0.0, _CODES[rule])[2] if rule in _CODES \
            else math.nan


assert L.N1 - L.C1 == L.KEPT1 - L.N1 == 2 * L.CS   # the contact blocks' layout
