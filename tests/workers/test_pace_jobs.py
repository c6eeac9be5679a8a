"""Workers fed the largest tasks first (issue 24) change no answer.

:func:`cadcnc.parallel.tasks.on_workers` hands the workers the tasks by decreasing size
and still returns (and reports) every result under its own task's index, and a worker
that dies is named by the caller's task number; one job runs here in task order.
"""

from __future__ import annotations

import os
import signal

import pytest

import cadcnc
from cadcnc.parallel.pool import START_ENV, WorkerError, kept_pools
from cadcnc.parallel.tasks import on_workers
from helpers.fixtures import FIXTURES


def _where(part, task, beat=None):
    """(task, faces of the part, worker's pid)."""
    return task, len(part), os.getpid()


@pytest.fixture(scope="module")
def part():
    return cadcnc.load_step(FIXTURES / "step_block.step")


def test_largest_first_keeps_every_result_in_its_place(part):
    tasks = list(range(9))
    sizes = [3, 9, 1, 9, 5, 0, 2, 8, 4]
    seen: list = []
    with kept_pools():
        out = on_workers(_where, tasks, part, 2, lambda k, res: seen.append((k, res[0])),
                         sizes=sizes)
        again = on_workers(_where, tasks, part, 2, sizes=sizes[::-1])
    assert [r[0] for r in out] == tasks and all(r[1] == len(part) for r in out)
    assert sorted(seen) == [(k, k) for k in tasks]   # each reported under its own index
    assert {r[2] for r in out} - {os.getpid()}       # the workers ran them
    assert not {r[2] for r in out} & {os.getpid()}
    # the pool is kept for the part: no worker beyond the pool's two, across both runs
    # (the first run may have been served by one of them alone: its tasks are instant)
    assert len({r[2] for r in again} | {r[2] for r in out}) <= 2


def test_one_job_runs_here_in_order(part):
    order: list = []
    out = on_workers(_where, [4, 1, 3], part, 1, lambda k, res: order.append(k),
                     sizes=[1, 2, 3])
    assert [r[0] for r in out] == [4, 1, 3] and order == [0, 1, 2]
    assert {r[2] for r in out} == {os.getpid()}


def _die_on_7(part, task, beat=None):
    if task == 7:
        os.kill(os.getpid(), signal.SIGKILL)
    return task


def test_a_dead_worker_is_named_by_the_callers_task_number(part):
    sizes = [0, 0, 0, 0, 0, 0, 0, 9]          # task 8 (index 7) goes first
    with pytest.raises(WorkerError, match=r"died during corner 8 of 8"):
        on_workers(_die_on_7, list(range(8)), part, 2, what="corner", sizes=sizes)


def _children() -> set[int]:
    """This process's live child processes."""
    out = set()
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            stat = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
        except (OSError, IndexError):   # gone meanwhile
            continue
        if int(stat[1]) == os.getpid() and stat[0] != "Z":
            out.add(int(pid))
    return out


def test_a_pool_lives_for_its_block_or_its_call(part, monkeypatch):
    """Inside ``kept_pools()`` a part's pool serves every call and ends with the block;
    outside, each call's pool ends with the call."""
    monkeypatch.setenv(START_ENV, "fork")
    before = _children()

    def pids() -> set[int]:
        return {r[2] for r in on_workers(_where, list(range(4)), part, 2)}

    with kept_pools() as pools:
        first, second = pids(), pids()
        assert len(first | second) <= 2 and pools.held(part)
        assert first | second <= _children()
    assert not pools.held(part) and _children() <= before
    assert pids() and _children() <= before
