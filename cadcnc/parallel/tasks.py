"""An operation's independent pieces (finishing planes, pencil corners) on every core.

:func:`on_workers` runs ``fn(part, task, beat)`` for every task: here, in order, with the
operation's heartbeat when ``jobs`` is 1; else in worker processes
(:func:`.pool.map_ordered`) that rebuild the part from BRep bytes once each
(:mod:`cadcnc.geometry.part_bytes`) and run without the heartbeat (it cannot cross
processes: ``on_result`` reports each piece as it ends). Results come back in task
order, so the program does not depend on ``jobs``; given the tasks' ``sizes`` the
workers take the largest first (the last to end is then a small one). :func:`beside` runs
work of the caller's own in this process while the workers run theirs (a finishing
program's links beside its uncut report), so that no core waits for the other.
"""

from __future__ import annotations

from functools import partial
from typing import Callable, Sequence, TypeVar

from ..geometry.part_bytes import part_blob, part_from_blob
from .pool import map_ordered

T = TypeVar("T")


def on_workers(fn: Callable, tasks: Sequence, part, jobs: int | None,
               on_result: Callable[[int, object], None] | None = None, what: str = "task",
               beat=None, sizes: Sequence[float] | None = None,
               meanwhile: Callable[[], None] | None = None) -> list:
    """``[fn(part, t, beat) for t in tasks]`` on ``jobs`` processes (module doc); ``fn``
    a module-level function. ``sizes``: the tasks' expected costs (any unit);
    ``meanwhile()``: the caller's own work, done here while the workers run (:func:`beside`)."""
    if jobs == 1 or len(tasks) <= 1:
        return map_ordered(partial(fn, beat=beat), tasks, part=part, jobs=1,
                           build=part_from_blob, build_args=tuple, on_result=on_result,
                           meanwhile=meanwhile)
    order = list(range(len(tasks)))
    if sizes is not None:
        order.sort(key=lambda k: -sizes[k])  # stable: equal sizes keep their order
    told = None if on_result is None else (lambda i, res: on_result(order[i], res))
    out = map_ordered(partial(fn, beat=None), [tasks[k] for k in order], part=part,
                      jobs=jobs, build=part_from_blob, build_args=lambda: part_blob(part),
                      on_result=told, what=what, numbers=[k + 1 for k in order],
                      meanwhile=meanwhile)
    result: list = [None] * len(tasks)
    for i, k in enumerate(order):
        result[k] = out[i]
    return result


def beside(here: Callable[[], T], fn: Callable, tasks: Sequence, part, jobs: int | None,
           what: str = "task", sizes: Sequence[float] | None = None) -> tuple[T, list]:
    """``(here(), on_workers(fn, tasks, part, jobs, sizes=sizes))``: two independent
    pieces of work at once, ``here()`` in this process while the workers run the tasks
    (with ``jobs`` 1, or one task, one after the other). Neither may depend on the
    other; ``here()`` may hand the same workers tasks of its own (they queue behind)."""
    box: list = []
    out = on_workers(fn, tasks, part, jobs, what=what, sizes=sizes,
                     meanwhile=lambda: box.append(here()))
    return box[0], out
