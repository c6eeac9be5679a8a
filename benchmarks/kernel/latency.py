"""Per-step latency of a stepper, measured four ways (bench_kernel.py prints them).

- ``raw``: perf_counter_ns around each ``step()``, normal scheduling, GC off.
- ``fifo``: the same with the process pinned to one core under SCHED_FIFO (a controller's
  interpolation thread), when the OS allows it (root or CAP_SYS_NICE); else None.
- ``kernel``: ``replays`` identical steppers stepped in lockstep (same steps, same order)
  under the fifo setting; each step's time is the minimum over the replays. Interrupts
  and descheduling hit one replay at random, the kernel's own work (an exact
  classification included) hits all: this is the per-step work, without the machine.
- ``cpu``: time.thread_time_ns around each step (time on the CPU; descheduling excluded,
  interrupts handled on this thread's time and the timer's own cost included).

``machine`` times a compiled busy loop of the same median duration the ``fifo`` way: the
tail this machine adds to any work of that length.
"""

from __future__ import annotations

import gc
import math
import os
import time
from contextlib import contextmanager

import numba
import numpy as np

clock = time.perf_counter_ns


@contextmanager
def fifo():
    """Pinned to the last CPU under SCHED_FIFO (priority 50) inside the block; yields False
    (and changes nothing) where the OS refuses."""
    cpus = sorted(os.sched_getaffinity(0))
    try:
        os.sched_setaffinity(0, {cpus[-1]})
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(50))
    except (PermissionError, AttributeError, OSError):
        os.sched_setaffinity(0, set(cpus))
        yield False
        return
    try:
        yield True
    finally:
        os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
        os.sched_setaffinity(0, set(cpus))


@contextmanager
def gc_off():
    gc.collect()
    gc.disable()
    try:
        yield
    finally:
        gc.enable()


def timed_steps(steppers: list, n: int, timer=clock) -> np.ndarray:
    """(len(steppers), k) step times (us) of k <= n lockstep steps (fewer if one stops)."""
    out = np.empty((len(steppers), n))
    k = 0
    with gc_off():
        while k < n:
            done = False
            for r, st in enumerate(steppers):
                t0 = timer()
                dp = st.step()
                out[r, k] = timer() - t0
                done = done or dp is None
            if done:
                break
            k += 1
    return out[:, :k] / 1000.0


@numba.njit(cache=True, nogil=True)
def _spin(n: int) -> float:
    x = 0.0
    for k in range(n):
        x = x * 0.999999 + math.sqrt(k + 1.0)
    return x


def machine_floor(median_us: float, n: int) -> np.ndarray:
    """Times (us) of n calls of a compiled busy loop calibrated to ``median_us``, fifo way."""
    spins = 16
    while True:
        t = np.median([_timed(lambda: _spin(spins)) for _ in range(200)])
        if t >= median_us or spins > 1 << 24:
            break
        spins = int(spins * max(1.1, min(2.0, median_us / max(t, 1e-3))))
    out = np.empty(n)
    with fifo(), gc_off():
        for k in range(n):
            t0 = clock()
            _spin(spins)
            out[k] = clock() - t0
    return out / 1000.0


def _timed(fn) -> float:
    t0 = clock()
    fn()
    return (clock() - t0) / 1000.0


def latency(make_stepper, n: int, replays: int = 3) -> dict:
    """{method: step times (us) or None} for the methods of the module docstring;
    ``make_stepper()`` builds a fresh, identical stepper."""
    warm = make_stepper()
    for _ in range(2000):
        warm.step()
    res = {"raw": timed_steps([make_stepper()], n)[0]}
    with fifo() as ok:
        res["fifo"] = timed_steps([make_stepper()], n)[0] if ok else None
        lock = timed_steps([make_stepper() for _ in range(replays)], n) if ok else None
    res["kernel"] = lock.min(axis=0) if lock is not None else None
    res["cpu"] = timed_steps([make_stepper()], n, time.thread_time_ns)[0]
    base = res["fifo"] if res["fifo"] is not None else res["raw"]
    res["machine"] = machine_floor(float(np.median(base)), n)
    return res


def percentiles(us: np.ndarray) -> tuple[float, float, float, float]:
    """(p50, p99, p99.9, max) in us."""
    p50, p99, p999 = np.percentile(us, [50, 99, 99.9])
    return float(p50), float(p99), float(p999), float(us.max())
