"""``beside``: the caller's own work done while the workers run their tasks."""

from __future__ import annotations

import time

import pytest

import cadcnc
from cadcnc.parallel.pool import START_ENV
from cadcnc.parallel.tasks import beside
from helpers.fixtures import FIXTURES

PAUSE_S = 0.4


def _slow(part, task, beat=None):
    """A task: the part's face count, and when it ran (perf_counter is system-wide)."""
    t0 = time.perf_counter()
    time.sleep(PAUSE_S)
    return task, len(part), t0, time.perf_counter()


def _here() -> tuple[float, float]:
    t0 = time.perf_counter()
    time.sleep(PAUSE_S)
    return t0, time.perf_counter()


@pytest.fixture(scope="module")
def part():
    return cadcnc.load_step(FIXTURES / "step_block.step")


def test_the_callers_work_overlaps_the_workers(part, monkeypatch):
    monkeypatch.setenv(START_ENV, "fork")
    (h0, h1), out = beside(_here, _slow, [1, 2], part, 2)
    assert [o[:2] for o in out] == [(1, len(part)), (2, len(part))]   # in order
    starts, ends = [o[2] for o in out], [o[3] for o in out]
    # here() ran while the workers slept, not before or after them
    assert h0 < min(ends) and h1 > max(starts)


def test_one_process_does_the_same_work_in_turn(part):
    (h0, h1), out = beside(_here, _slow, [1, 2], part, 1)
    assert [o[:2] for o in out] == [(1, len(part)), (2, len(part))]
    assert h1 <= min(o[2] for o in out)   # here() first, then the tasks


def _fails() -> None:
    raise ValueError("the caller's work failed")


def test_a_failure_of_the_callers_work_stops_the_workers(part, monkeypatch):
    monkeypatch.setenv(START_ENV, "fork")
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="caller's work failed"):
        beside(_fails, _slow, [1, 2, 3, 4, 5, 6], part, 2)
    # the queued tasks were cancelled and the workers killed, not waited for (6 x 0.4 s
    # on 2 workers)
    assert time.perf_counter() - t0 < 3 * PAUSE_S
