"""Gates of many cuts at once: one task per cut, on every core (:mod:`cadcnc.parallel`).

:func:`gate_cuts` gates each ``(toolpath, moves, blend)`` on the part and returns the
:class:`~cadcnc.verification.gate.GateResult` of each, in order, whatever the number of
processes; the workers take the longest cuts first. In a worker the part is rebuilt
from BRep bytes once (:mod:`cadcnc.geometry.part_bytes`). What a gate found that the
next gate of the same cut can reuse (the pair's checks, exact distances: :mod:`.gate_cache`) comes back with
its result and is handed to the next one: the cut-back step and the program gate share
it in whichever processes they run.
"""

from __future__ import annotations

from ..core.tolerances import Tolerances
from ..parallel.tasks import on_workers
from .gate import GateResult, gouge_gate
from .gate_cache import cache_for, open_shared, toolpath_key
from .surface_checks import resolve_part


def _gate_task(part, task, beat=None) -> tuple[GateResult, tuple | None]:
    """One cut's gate (in a worker or here) and, when asked, what it found to share."""
    toolpath, moves, blend, before, tol, reference, share, want = task
    since = 0
    if want:  # a worker: its gates share their work while its pool lives
        open_shared(part)
    if not reference:
        cache = cache_for(part, tol)
        cache.take(share)
        since = len(cache.memo)
    result = gouge_gate(toolpath, part, tol, moves=moves, blend_mm=blend, reference=reference,
                        before=before)
    out = cache.share(toolpath_key(toolpath), since) if want and not reference else None
    return result, out


def gate_cuts(part, items: list, tol: Tolerances, *, jobs: int | None = 1,
              reference: bool = False, progress=None) -> list[GateResult]:
    """The gate of each ``(toolpath, moves or None, blend_mm, before or None)`` of ``items``
    on ``part`` (``before``: :func:`~.gate.gouge_gate`'s).

    ``jobs``: processes (None: every core; 1: here, in order). ``progress(done, total,
    "cuts")`` as each gate ends."""
    if part is None and items:  # the part the first cut's job names, read once
        part = resolve_part(items[0][0], None)
    shares = None if reference else cache_for(part, tol).shares
    many = jobs != 1 and len(items) > 1
    tasks = [(tp, moves, float(blend), before, tol, reference,
              None if shares is None or not many else shares.get(toolpath_key(tp)), many)
             for tp, moves, blend, before in items]
    count = [0]

    def arrived(k: int, res) -> None:
        count[0] += 1
        if shares is not None and res[1] is not None:
            shares[res[1][0]] = _merged(shares.get(res[1][0]), res[1])
        if progress is not None:
            progress(count[0], len(tasks), "cuts")

    sizes = [len(tp.points) + (0 if moves is None else len(moves)) for tp, moves, *_ in items]
    out = on_workers(_gate_task, tasks, part, jobs, arrived, "the gate of cut", sizes=sizes)
    return [r for r, _ in out]


def _merged(old: tuple | None, new: tuple) -> tuple:
    """Two shares of one toolpath as one."""
    if old is None:
        return new
    return new[0], new[1] if new[1] is not None else old[1], {**old[2], **new[2]}
