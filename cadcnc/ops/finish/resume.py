"""Where a finishing pass resumes past a collision, and the exact point it lands on.

A cut stopped on ``collision`` (the guard: another face, or the shank) resumes where the
plane's offset curve is clear again: :func:`free_run` runs on without the guard, in runs
of ``FREE_CHUNK`` cycles that double (so that a long face is not run to its end at every
collision: the work stays proportional to the distance to the clear point);
:func:`clear_again` lands back from the first clear point on the clearance's zero, and
:func:`land_exact` puts a landed point exactly on the offset curve and the zero. The
functions take the pass (``ps``, :class:`~cadcnc.ops.finish.passes._Pass`'s interface:
``job``, ``nrm``, ``plane``, ``run_stepper``, ``skip``). Lengths mm.
"""

from __future__ import annotations

import numpy as np

from ...interp.cycle import COLLISION, MAX_CYCLES
from ...interp.stepper import Tangency
from ...program.toolpath import Toolpath
from .polish import polish

RESUME_STEPS = 4     # cycles allowed to the run landing back on a clearance's zero
FREE_CHUNK = 256
"""Cycles of the first free run past a collision (doubled until the curve is clear)."""
PASS_CYCLES = 1_000_000
"""Interpolation cycles of one stepper run (a piece, a free run past a collision)."""


def land_exact(ps, surface, clear: np.ndarray, beyond: np.ndarray, uv, guard):
    """The point of the exact offset curve between ``clear`` and ``beyond`` (mm;
    ``beyond`` one step past a landed point) where the guard's clearance reaches 0, on
    its clear side (bisection to 1e-10 of the chord): (centre, uv, contact, normal),
    or None when the curve is clear up to ``beyond``."""
    def on_curve(x: float):
        return polish(surface, ps.job.tool.offset, ps.nrm, ps.plane.offset,
                      (clear + x * (beyond - clear))[None], np.asarray(uv)[None])

    best = on_curve(1.0)
    if guard.margin(tuple(best[0][0]))[0] >= 0.0:
        return None
    lo, hi, best = 0.0, 1.0, on_curve(0.0)
    for _ in range(34):
        mid = 0.5 * (lo + hi)
        found = on_curve(mid)
        if guard.margin(tuple(found[0][0]))[0] >= 0.0:
            lo, best = mid, found
        else:
            hi = mid
    return tuple(a[0] for a in best)


def clear_again(ps, face: int, at: Tangency, end, guard, why: str) -> Tangency | None:
    """Where the plane's curve on ``face`` past a collision at ``at`` is clear again:
    run on without the guard, take the first clear point after a hit, and land back
    from it on the clearance's zero. Skips the stretch in between (``collision``)."""
    free, k, hit = ps.free_run(face, at, end, guard)
    if k is None or not hit:
        ps.skip(face, COLLISION, f"from {xyz(at.p)} to {xyz(free.points[-1])} "
                f"({why})", (at.p, end.p if end is not None else free.points[-1]))
        return None
    clear = state_at(free, k)
    back = ps.run_stepper(face, clear, None, guard, backwards=True,
                          max_cycles=RESUME_STEPS)
    resume = last_state(back) if back.stop_reason == COLLISION else clear
    ps.skip(face, COLLISION, f"from {xyz(at.p)} to {xyz(resume.p)} ({why})",
            (at.p, resume.p))
    return resume


def free_run(ps, face: int, at: Tangency, end, guard):
    """(free, k, hit): the plane's curve on ``face`` from ``at`` run without the guard,
    in runs of FREE_CHUNK cycles doubling, until a clear point after a hit (index k,
    else None) or its end; ``hit``: whether the guard's margin went negative (the guard
    asked along the run: :meth:`~cadcnc.guard.clearance.ClearanceGuard.clear_along`)."""
    chunk, start, hit, total = FREE_CHUNK, at, False, 0
    while True:
        free = ps.run_stepper(face, start, end, None, max_cycles=chunk)
        total += chunk
        clear = guard.clear_along(free.points[1:])
        for k, ok in enumerate(clear, 1):
            hit = hit or not ok
            if ok and hit:
                return free, k, hit
        from_max = free.stop_reason == MAX_CYCLES and len(free) > 1
        if not from_max or total >= PASS_CYCLES:
            return free, (len(clear) if clear and clear[-1] else None), hit
        start, chunk = last_state(free), min(2 * chunk, PASS_CYCLES - total)



def state_at(tp: Toolpath, k: int) -> Tangency:
    """The stepper's state at point ``k`` of ``tp``."""
    return Tangency(tuple(map(float, tp.points[k])), tuple(map(float, tp.uv[k, 0])),
                    tuple(map(float, tp.uv[k, 1])))


def last_state(tp: Toolpath) -> Tangency:
    """The stepper's state at the last point of ``tp``."""
    return state_at(tp, len(tp) - 1)


def xyz(p) -> str:
    """``(x, y, z)`` to 3 decimals (mm)."""
    return "(" + ", ".join(f"{float(v):.3f}" for v in p) + ")"
