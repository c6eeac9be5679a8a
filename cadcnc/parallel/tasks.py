"""An operation's independent pieces (finishing planes, pencil corners) on every core.

:func:`on_workers` runs ``fn(part, task, beat)`` for every task: here, in order, with the
operation's heartbeat when ``jobs`` is 1; else in worker processes
(:func:`.pool.map_ordered`) that rebuild the part from BRep bytes once each
(:mod:`cadcnc.geometry.part_bytes`) and run without the heartbeat (it cannot cross
processes: ``on_result`` reports each piece as it ends). Results come back in task
order, so the program does not depend on ``jobs``; given the tasks' ``sizes`` the
workers take the largest first (the last to end is then a small one).
"""

from __future__ import annotations

from functools import partial
from typing import Callable, Sequence

from ..geometry.part_bytes import part_blob, part_from_blob
from .pool import map_ordered


def on_workers(fn: Callable, tasks: Sequence, part, jobs: int | None,
               on_result: Callable[[int, object], None] | None = None, what: str = "task",
               beat=None, sizes: Sequence[float] | None = None) -> list:
    """``[fn(part, t, beat) for t in tasks]`` on ``jobs`` processes (module doc); ``fn``
    a module-level function. ``sizes``: the tasks' expected costs (any unit)."""
    if jobs == 1 or len(tasks) <= 1:
        return map_ordered(partial(fn, beat=beat), tasks, part=part, jobs=1,
                           build=part_from_blob, build_args=tuple, on_result=on_result)
    order = list(range(len(tasks)))
    if sizes is not None:
        order.sort(key=lambda k: -sizes[k])  # stable: equal sizes keep their order
    told = None if on_result is None else (lambda i, res: on_result(order[i], res))
    out = map_ordered(partial(fn, beat=None), [tasks[k] for k in order], part=part,
                      jobs=jobs, build=part_from_blob, build_args=lambda: part_blob(part),
                      on_result=told, what=what, numbers=[k + 1 for k in order])
    result: list = [None] * len(tasks)
    for i, k in enumerate(order):
        result[k] = out[i]
    return result
