"""An operation's independent pieces (finishing planes, pencil corners) on every core.

:func:`on_workers` runs ``fn(part, task, beat)`` for every task: here, in order, with the
operation's heartbeat when ``jobs`` is 1; else in worker processes
(:func:`cadcnc.workers.map_ordered`) that rebuild the part from BRep bytes once each
(:mod:`cadcnc.geometry.part_bytes`) and run without the heartbeat (it cannot cross
processes: ``on_result`` reports each piece as it ends). Results come back in task
order, so the program does not depend on ``jobs``; given the tasks' ``sizes`` the
workers take the largest first (the last to end is then a small one).

:func:`start_workers` starts the pool in the background while the operation plans (the
workers' start-up, imports and the part's rebuild, then overlaps the caller's serial
work instead of following it).
"""

from __future__ import annotations

import threading
from functools import partial
from typing import Callable, Sequence

from ..geometry.part_bytes import part_blob, part_from_blob
from ..workers import check_jobs, map_ordered

_STARTING: dict[int, tuple[object, threading.Thread, list]] = {}  # id(part) -> start-up


def _ready(part, task) -> None:
    """A task that does nothing: the pool is up once every worker has run one."""
    return None


def start_workers(part, jobs: int | None) -> None:
    """Start ``jobs`` workers for ``part`` in a background thread (no-op for one job);
    :func:`on_workers` waits for them. The part's BRep bytes are made here, in the
    caller's thread (OCCT is not asked for them from two threads at once)."""
    n = check_jobs(jobs)
    if n == 1 or id(part) in _STARTING:
        return
    blob = part_blob(part)
    errors: list = []

    def run() -> None:
        try:
            map_ordered(_ready, [None] * n, part=part, jobs=n, build=part_from_blob,
                        build_args=lambda: blob, what="the workers' start")
        except BaseException as e:  # noqa: BLE001 - raised again by on_workers
            errors.append(e)

    thread = threading.Thread(target=run, daemon=True)
    _STARTING[id(part)] = (part, thread, errors)
    thread.start()


def workers_ready(part) -> None:
    """Wait for :func:`start_workers`' pool of ``part`` (if any); raise its error."""
    held = _STARTING.pop(id(part), None)
    if held is None or held[0] is not part:
        return
    held[1].join()
    if held[2]:
        raise held[2][0]


def on_workers(fn: Callable, tasks: Sequence, part, jobs: int | None,
               on_result: Callable[[int, object], None] | None = None, what: str = "task",
               beat=None, sizes: Sequence[float] | None = None) -> list:
    """``[fn(part, t, beat) for t in tasks]`` on ``jobs`` processes (module doc); ``fn``
    a module-level function. ``sizes``: the tasks' expected costs (any unit)."""
    workers_ready(part)
    if jobs == 1 or len(tasks) <= 1:
        return map_ordered(partial(fn, beat=beat), tasks, part=part, jobs=1,
                           build=part_from_blob, build_args=tuple, on_result=on_result)
    order = list(range(len(tasks)))
    if sizes is not None:
        order.sort(key=lambda k: -sizes[k])  # stable: equal sizes keep their order
    told = None if on_result is None else (lambda i, res: on_result(order[i], res))
    out = map_ordered(partial(fn, beat=None), [tasks[k] for k in order], part=part,
                      jobs=jobs, build=part_from_blob, build_args=lambda: part_blob(part),
                      on_result=told, what=what)
    result: list = [None] * len(tasks)
    for i, k in enumerate(order):
        result[k] = out[i]
    return result
