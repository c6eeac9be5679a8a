"""The workers' warm-up (cadcnc/parallel/warm.py, issue 24): a fresh process that runs it has
a kernel's compiled code loaded from numba's cache before its first call, and compiles
nothing afresh."""

from __future__ import annotations

import subprocess
import sys

import pytest

pytestmark = pytest.mark.slow  # two subprocesses that start and warm workers: about 26 s

CALL = ("from cadcnc.interp.kernel.cycle_math import dot; "
        "assert dot((1.0, 2.0, 3.0), (1.0, 1.0, 1.0)) == 6.0")
WARM = ("import cadcnc.interp.kernel.cycle_math as m; from cadcnc.parallel.warm import warm; "
        "before = len(m.dot.overloads); n = warm(); "
        "print(before, len(m.dot.overloads), n, sum(m.dot.stats.cache_misses.values()))")


def _python(code: str) -> str:
    return subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                          text=True).stdout


def test_warm_loads_cached_kernels_before_their_first_call():
    _python(CALL)   # the kernel in numba's cache (a fresh checkout has none yet)
    before, after, loaded, misses = map(int, _python(WARM).split())
    assert before == 0 and after >= 1 and loaded >= after
    assert misses == 0   # loaded from the cache, not compiled


START = ("import multiprocessing.forkserver as f; from cadcnc.parallel import pool; "
         "pool.start(1); one = f._forkserver._forkserver_pid; "
         "pool.start(2); print(one, f._forkserver._forkserver_pid)")


def test_the_workers_server_starts_early_only_for_more_than_one_process(monkeypatch):
    monkeypatch.setenv("CADCNC_START_METHOD", "forkserver")   # a threaded caller's
    one, two = _python(START).split()
    assert one == "None" and int(two) > 0
    monkeypatch.delenv("CADCNC_START_METHOD")   # a command's: its workers are forks
    assert _python(START).split() == ["None", "None"]
