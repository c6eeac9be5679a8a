"""Independent tasks on every core: a standard-library process pool, results in order.

Operations (pencil corners, finishing planes) and the gouge gate (one task per cut) hand
:func:`map_ordered` a function and a list of tasks. With ``jobs`` 1 (or one task) the
tasks run here, in order, on the caller's part; else in a
``concurrent.futures.ProcessPoolExecutor``. How its workers start (:func:`start_method`):

- *fork* (the default on Linux, in a process running no other Python thread): each worker
  is a copy of this process, with the part, its faces and what was built for it before
  the pool started (compiled kernels, an operation's guards) at no cost;
- *forkserver* (in a process that runs other threads, where a copy could inherit a lock
  another thread holds, and hang): workers are forked from a server that has the
  library imported and its compiled kernels loaded (:data:`PRELOAD`), and rebuild the
  part once each (the ``build`` function and its arguments, e.g. BRep bytes: OCCT
  shapes do not pickle); :func:`start` starts the server early, while the caller still
  reads the part and plans;
- *spawn* where there is no fork.

Pools are owned by a :class:`Pools` block: ``with kept_pools():`` (a command's run of
one part) keeps each part's pool for the block, reused by the next call with the same
part (the gate after the computation), and shuts every one down at its end; a pool for
another part shuts the idle kept ones down first. Outside such a block, each
:func:`map_ordered` call owns its pool for the call.

Results come back in task order whatever the number of workers, so outputs do not
depend on it. ``on_result(k, result)`` is called in the caller's process as each
result arrives (progress). Ctrl-C cancels the pending tasks, terminates every worker
and re-raises KeyboardInterrupt; a worker that dies raises :class:`WorkerError` (exit 1)
naming the task, never a hang. No OCCT here: the part is opaque.
"""

from __future__ import annotations

import gc
import multiprocessing
import multiprocessing.forkserver
import os
import signal
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, Callable, Iterator, Sequence

from ..core.errors import CadcncError, InputError

PRELOAD = ["cadcnc.ops.run", "cadcnc.verification.gate_jobs", "cadcnc.parallel.server"]
"""Modules the workers' server imports once, by name (every worker starts with them
loaded; the last loads the compiled kernels of the others: :mod:`.server`)."""
ENV = "CADCNC_JOBS"
"""The default number of processes when none is given (unset: every core)."""
START_ENV = "CADCNC_START_METHOD"
"""How workers start when set (fork, forkserver or spawn); unset: :func:`start_method`."""
WATCH_S = 0.5
"""How often (s) a worker checks that its parent process is still there."""
KILL_AFTER_S = 2.0
"""How long (s) a terminated worker has to end before it is killed outright."""
_IN_WORKER: dict[str, Any] = {}
"""Owned by a worker process: the part its initializer rebuilt (or inherited), for its
life. Empty in the caller's process."""


class WorkerError(CadcncError):
    """A worker process died (killed, out of memory, crashed in native code): exit 1."""


def default_jobs() -> int:
    """The environment's ``CADCNC_JOBS`` when set, else all cores this process may use."""
    env = os.environ.get(ENV, "").strip()
    if env:
        if not env.isdigit() or int(env) < 1:
            raise InputError(f"{ENV}={env!r}: a whole number of processes >= 1")
        return int(env)
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return max(os.cpu_count() or 1, 1)


def check_jobs(jobs: int | None) -> int:
    """``jobs`` as a worker count (None: every core); InputError below 1."""
    if jobs is None:
        return default_jobs()
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise InputError(f"jobs (--jobs) must be a whole number of processes >= 1, got {jobs!r}")
    return jobs


def start(jobs: int | None) -> None:
    """Start the workers' server now when ``jobs`` asks for more than one process (None:
    every core), so that its imports and warm-up (:data:`PRELOAD`, a few seconds) run on
    another core while this process reads the part and plans; the pools started later
    fork their workers from it at once. InputError for a bad ``jobs``."""
    if check_jobs(jobs) > 1 and start_method() == "forkserver":
        _context()   # sets the server's preload before it starts
        multiprocessing.forkserver.ensure_running()


def start_method() -> str:
    """How workers start: ``CADCNC_START_METHOD`` when set; else ``fork`` when this
    process runs no Python thread beside its main one, ``forkserver`` when it does (a
    GUI, a Dask worker, a kept pool's threads), ``spawn`` where there is no fork (module
    doc). Native thread pools are not counted: BLAS's prepare for a fork themselves, and
    no worker task runs OCCT's parallel algorithms. InputError for an unknown method."""
    methods = multiprocessing.get_all_start_methods()
    env = os.environ.get(START_ENV, "").strip()
    if env:
        if env not in methods:
            raise InputError(f"{START_ENV}={env!r}: one of {', '.join(methods)}")
        return env
    if "fork" in methods and threading.active_count() == 1:
        return "fork"
    return "forkserver" if "forkserver" in methods else "spawn"


def _init(build: Callable, args: tuple, parent: int) -> None:
    """In a worker: rebuild the part once (imports and compiled kernels come with it), or
    take the parent's (``build`` :func:`_inherited`: a forked worker has it already).
    Ctrl-C is the parent's to handle: it terminates the workers; a worker whose parent
    is gone (killed, or ended by ``os._exit``) ends too."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_watch, args=(parent,), daemon=True).start()
    _IN_WORKER["part"] = build(*args)
    # What the worker started with (the parent's modules and part, copied by the fork,
    # or rebuilt) lives as long as it does: its collector need not walk those objects
    # again (0.2 s a worker on a finishing program), nor touch their shared pages.
    gc.freeze()


def _watch(parent: int) -> None:
    while True:
        time.sleep(WATCH_S)
        if not process_alive(parent):
            os._exit(1)


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` runs: not gone, and not a zombie (a parent that has exited
    but is not yet reaped still answers ``kill(pid, 0)``; a worker it started without
    registering, e.g. at a Ctrl-C, would then wait for it, holding its output pipes)."""
    try:
        os.kill(pid, 0)
    except OSError:
        return False
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            state = f.read().rsplit(b")", 1)[1].split()[0]
    except (OSError, IndexError):  # no /proc (not Linux), or gone meanwhile
        return True
    return state not in (b"Z", b"X")


def _call(fn: Callable, task) -> Any:
    return fn(_IN_WORKER["part"], task)


def _inherited(part):
    """A forked worker's part: its parent's, copied by the fork."""
    return part


def _context():
    """The multiprocessing context of :func:`start_method` (the server's preload set)."""
    method = start_method()
    ctx = multiprocessing.get_context(method)
    if method == "forkserver":
        ctx.set_forkserver_preload(PRELOAD)
    return ctx


def _shutdown(pool: ProcessPoolExecutor, kill: bool = False) -> None:
    """End a pool: after its running tasks, or (``kill``) now."""
    if not kill:
        pool.shutdown(wait=True, cancel_futures=True)
        return
    # Ctrl-C or a dead worker: stop every worker now, not after its task.
    procs = [p for p in list(getattr(pool, "_processes", {}).values()) if p.is_alive()]
    for proc in procs:
        proc.terminate()
    deadline = time.monotonic() + KILL_AFTER_S
    for proc in procs:
        proc.join(max(deadline - time.monotonic(), 0.0))
        if proc.is_alive():
            proc.kill()
            proc.join(KILL_AFTER_S)
    # The pool's own teardown frees its queues (else Python warns of leaked semaphores),
    # but is given a bounded time: its queue threads can block on a pipe no one reads.
    ender = threading.Thread(target=pool.shutdown, kwargs={"cancel_futures": True}, daemon=True)
    ender.start()
    ender.join(KILL_AFTER_S)


def _number(bad: list[int], numbers: Sequence[int] | None) -> str:
    """The number of the first task that did not finish, as the caller counts them."""
    if not bad:
        return "?"
    return str(numbers[bad[0]] if numbers is not None else bad[0] + 1)


@contextmanager
def _ctrl_c_deferred() -> Iterator[None]:
    """Hold a Ctrl-C (SIGINT) until the block ends. Submitting starts the pool's workers;
    a Ctrl-C between a worker's start and its registration would leave it running,
    unknown to the pool, and printing a traceback when it finds its queues gone."""
    if threading.current_thread() is not threading.main_thread() or \
            not hasattr(signal, "pthread_sigmask"):
        yield
        return
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


class Pools:
    """The worker pools of a block (module doc): one per part and worker count, kept until
    :meth:`close` (the end of the ``with`` block)."""

    def __init__(self) -> None:
        self._held: dict[int, tuple[Any, int, ProcessPoolExecutor]] = {}  # id(part) -> ...
        self._busy: dict[int, int] = {}   # id(part) -> its map_ordered calls running now
                                          # (another thread's, or nested in a meanwhile)
        self._lock = threading.Lock()

    def __enter__(self) -> "Pools":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def get(self, part, jobs: int, build: Callable, args: Callable[[], tuple]
            ) -> ProcessPoolExecutor:
        """The pool of ``part`` with ``jobs`` workers, started on first use."""
        held = self._held.get(id(part))
        if held is not None and held[0] is part and held[1] == jobs:
            return held[2]
        for key in [k for k in self._held if k not in self._busy]:
            self.end(key)   # idle pools: their threads gone, this one's workers can be forks
        ctx = _context()
        if ctx.get_start_method() == "fork":   # the part is not pickled: the fork copies it
            initargs = (_inherited, (part,), os.getpid())
        else:
            initargs = (build, args(), os.getpid())
        pool = ProcessPoolExecutor(jobs, mp_context=ctx, initializer=_init, initargs=initargs)
        self._held[id(part)] = (part, jobs, pool)
        return pool

    def held(self, part) -> bool:
        """Whether a pool of ``part`` is kept."""
        return id(part) in self._held

    def end(self, key: int, kill: bool = False) -> None:
        """Shut the pool of ``id(part)`` down (``kill``: now), if it is kept."""
        held = self._held.pop(key, None)
        if held is not None:
            _shutdown(held[2], kill)

    @contextmanager
    def busy(self, part) -> Iterator[None]:
        """Mark ``part``'s pool as running tasks: another part's call leaves it alone
        (nested calls counted: a ``meanwhile`` may run tasks of its own on the pool)."""
        key = id(part)
        with self._lock:
            self._busy[key] = self._busy.get(key, 0) + 1
        try:
            yield
        finally:
            with self._lock:
                self._busy[key] -= 1
                if not self._busy[key]:
                    del self._busy[key]

    def close(self) -> None:
        """Shut every kept pool down (its workers exit)."""
        for key in list(self._held):
            self.end(key)


_KEPT: ContextVar[Pools | None] = ContextVar("cadcnc_kept_pools", default=None)
"""The :class:`Pools` of the innermost :func:`kept_pools` block (None outside any)."""


@contextmanager
def kept_pools() -> Iterator[Pools]:
    """Keep each part's worker pool for the block and shut them all down at its end
    (module doc); blocks nest (the outer one keeps the pools)."""
    outer = _KEPT.get()
    if outer is not None:
        yield outer
        return
    pools = Pools()
    token = _KEPT.set(pools)
    try:
        with pools:
            yield pools
    finally:
        _KEPT.reset(token)


@contextmanager
def _pools() -> Iterator[Pools]:
    """The kept pools of the current block, else pools for this call only."""
    kept = _KEPT.get()
    if kept is not None:
        yield kept
        return
    with Pools() as pools:
        yield pools


def map_ordered(fn: Callable[[Any, Any], Any], tasks: Sequence, *, part, jobs: int | None,
                build: Callable, build_args: Callable[[], tuple],
                on_result: Callable[[int, Any], None] | None = None,
                what: str = "task", numbers: Sequence[int] | None = None,
                meanwhile: Callable[[], None] | None = None) -> list:
    """``[fn(part, t) for t in tasks]``, on ``jobs`` processes (module doc).

    ``meanwhile()``: work of the caller's own, run in this process while the workers
    run the tasks (before them with one process); results are taken after it returns.

    ``fn`` must be a module-level function (it is pickled by name); ``build(*build_args())``
    rebuilds ``part`` in a worker (``build_args`` is called only when a pool starts).
    ``what(k)``-style naming: ``what`` names a task in the dead-worker error, and
    ``numbers[k]`` its number there (default ``k + 1``: tasks handed out reordered keep
    the caller's numbers).
    """
    tasks = list(tasks)
    jobs = min(check_jobs(jobs), max(len(tasks), 1))
    if jobs == 1:
        if meanwhile is not None:
            meanwhile()
        out = []
        for k, t in enumerate(tasks):
            out.append(fn(part, t))
            if on_result is not None:
                on_result(k, out[-1])
        return out
    with _pools() as pools, pools.busy(part):
        return _run(pools, fn, tasks, part, jobs, build, build_args, on_result, what, numbers,
                    meanwhile)


def _run(pools: Pools, fn: Callable, tasks: list, part, jobs: int, build: Callable,
         build_args: Callable[[], tuple], on_result, what: str,
         numbers: Sequence[int] | None, meanwhile: Callable[[], None] | None) -> list:
    """:func:`map_ordered` on the pool of ``part`` in ``pools``."""
    pool = pools.get(part, jobs, build, build_args)
    futures = {}
    try:
        with _ctrl_c_deferred():  # the pool starts its workers here: all or none registered
            futures = {pool.submit(_call, fn, t): k for k, t in enumerate(tasks)}
        if meanwhile is not None:
            meanwhile()
        out: list = [None] * len(tasks)
        pending = set(futures)
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for f in sorted(done, key=futures.get):
                out[futures[f]] = f.result()
                if on_result is not None:
                    on_result(futures[f], out[futures[f]])
        return out
    except BrokenProcessPool as e:
        bad = sorted(k for f, k in futures.items() if not f.done() or f.exception())
        pools.end(id(part), kill=True)
        raise WorkerError(f"a worker process died during {what} {_number(bad, numbers)} "
                          f"of {len(tasks)} (killed, out of memory, or a crash in native "
                          "code); nothing written. --jobs 1 runs in one process") from e
    except BaseException:  # Ctrl-C, or an error in a task: stop every worker
        pools.end(id(part), kill=True)
        raise
