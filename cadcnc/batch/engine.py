"""Run a batch of parts on Dask distributed: each part one task (:func:`run_part`, every
operation in one process), on an embedded local cluster of worker processes (loopback
only, nothing to start) or on an existing cluster (``scheduler="tcp://HOST:PORT"``).

Before any task: every part is read and hashed, and every output destination checked;
a part whose last run had the same hash and left all its outputs is skipped. A worker
that dies while running a part has its task run again elsewhere (Dask's
``allowed-failures``); the summary reports the attempts. The outputs come back from the
workers as bytes and are written here, all or nothing per operation.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import dask
from distributed import Client, LocalCluster, as_completed
from distributed.client import FutureCancelledError
from distributed.scheduler import KilledWorker

from ..core.errors import EXIT_INTERNAL, InputError, OutputError
from ..io.output_set import OutputSet, check_not_inputs
from ..io.outputs import SUFFIXES
from .records import STATE, Record, job_hash, save_state, unchanged, write_summary
from .task import EVENT_TOPIC, BatchPart, OperationResult, PartResult, run_part

ALLOWED_FAILURES = 2
"""Workers that may die running one part before the embedded cluster gives up on it (a
part that kills every worker it runs on is reported failed, exit 1)."""
CONNECT_TIMEOUT_S = 10.0
"""How long ``--scheduler`` may take to answer."""


@dataclass
class Progress:
    """Parts of the batch: ``total``, ``done`` (finished, failed ones included, skipped
    ones not), ``running`` (started on a worker), ``failed``, ``skipped``."""

    total: int
    done: int = 0
    running: int = 0
    failed: int = 0
    skipped: int = 0

    def __str__(self) -> str:
        return (f"{self.done + self.skipped}/{self.total} done ({self.skipped} skipped), "
                f"{self.running} running, {self.failed} failed")


@dataclass
class _Planned:
    part: BatchPart
    folder: Path
    digest: str
    sets: list[OutputSet]


def run_batch(parts: Sequence[BatchPart], out, *, scheduler: str | None = None,
          workers: int | None = None, force: bool = False,
          progress: Callable[[Progress], None] | None = None, inputs=()) -> list[Record]:
    """Run every part's operations and return the summary's records (one per part and
    operation, in the parts' order); also written to OUT/summary.csv and .json. Outputs
    go to OUT/NAME/ (NAME: the part's name). ``scheduler``: an existing Dask scheduler's
    address (default: an embedded local cluster of ``workers`` processes, default one per
    core); ``force``: run unchanged parts again; ``progress``: called with a
    :class:`Progress` whenever a part starts or ends; ``inputs``: other files the batch
    reads (its job file). No output may be an input: every part, every file of
    ``inputs`` (OutputIsInputError naming both, exit 2, before any work)."""
    out = Path(out)
    plans = _plan(list(parts), out, inputs)
    state = Progress(len(plans))
    records: dict[str, list[Record]] = {}
    todo = []
    for p in plans:
        names = [f for s in p.sets for f in (d.name for d in s.destinations)]
        again = None if force else unchanged(p.folder, p.digest, names)
        if again is None:
            todo.append(p)
        else:
            records[p.part.label] = again
            state.skipped += 1
    if progress:
        progress(state)
    if todo:
        with connect(scheduler, workers, len(todo)) as client:
            records.update(_run(client, todo, state, progress))
    result = [r for p in plans for r in records[p.part.label]]
    write_summary(out, result)
    return result


def _plan(parts: list[BatchPart], out: Path, inputs=()) -> list[_Planned]:
    """Each part hashed and its destinations checked (InputError, OutputError) before any
    work, every destination against every input; the folders made."""
    if not parts:
        raise InputError("a batch needs at least one part")
    seen: dict[str, str] = {}
    for p in parts:
        if not isinstance(p, BatchPart):
            raise InputError(f"parts must be cadcnc.batch.BatchPart, got {type(p).__name__}")
        if p.label in seen:
            raise InputError(f"{p.path} and {seen[p.label]} would share the output folder "
                             f"{p.label!r}: give one of them a name")
        seen[p.label] = p.path
        names = [name for op in p.operations for name in op.outputs]
        if not p.operations or len(set(names)) < len(names):
            raise InputError(f"{p.path}: no operation, or two that write one file: "
                             f"{', '.join(names)}")
    check_not_inputs([out / "summary.csv", out / "summary.json"] + [
        out / p.label / name for p in parts
        for name in [STATE, *(n for op in p.operations for n in op.outputs)]],
        [p.path for p in parts] + list(inputs))
    digests = [job_hash(p) for p in parts]   # every part read before any folder is made
    plans = []
    for p, digest in zip(parts, digests):
        folder = out / p.label
        folder.mkdir(parents=True, exist_ok=True)
        sets = [OutputSet([folder / name for name in op.outputs], SUFFIXES)
                for op in p.operations]
        plans.append(_Planned(p, folder, digest, sets))
    return plans


@contextlib.contextmanager
def connect(scheduler: str | None, workers: int | None, tasks: int):
    """A Dask client on ``scheduler``, or on an embedded local cluster of worker processes
    (one thread each: the work is CPU-bound and holds the GIL) listening on loopback."""
    if scheduler:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError) as e:
            raise InputError(f"--scheduler {scheduler}: no Dask scheduler answers ({e})") \
                from None
        with client:
            yield client
        return
    n = workers or min(os.cpu_count() or 1, tasks)
    if n < 1:
        raise InputError(f"--workers must be at least 1, got {n}")
    with dask.config.set({"distributed.scheduler.allowed-failures": ALLOWED_FAILURES}):
        # no dashboard; the scheduler's HTTP endpoints on a free loopback port
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               host="127.0.0.1", scheduler_port=0, dashboard_address=None,
                               scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                               silence_logs=logging.ERROR)
    with cluster, Client(cluster) as client:
        yield client


def _run(client: Client, todo: list[_Planned], state: Progress, progress) -> dict:
    """Submit one task per part, follow their start events and write each part's outputs
    as it ends; the records by part name."""
    lock = threading.Lock()
    started: set[str] = set()
    finished: set[str] = set()

    token = uuid.uuid4().hex

    def on_start(event) -> None:
        if event[1].get("batch") != token:
            return
        name = event[1]["part"]
        with lock:
            if name in finished or name in started:
                return
            started.add(name)
            state.running += 1
            if progress:
                progress(state)

    client.subscribe_topic(EVENT_TOPIC, on_start)
    futures = {client.submit(run_part, p.part, token, key=f"cadcnc-{p.part.label}-{token}",
                             pure=False, priority=-rank): p
               for rank, p in enumerate(sorted(todo, key=lambda p: -queue_size(p.part)))}
    records: dict[str, list[Record]] = {}
    for future in as_completed(futures):
        plan = futures[future]
        try:
            result: PartResult | str = future.result()
        except KilledWorker as e:
            result = f"the workers running it died too often (Dask's allowed-failures): {e}"
        except (FutureCancelledError, OSError) as e:
            result = f"lost: {type(e).__name__}: {e}"
        records[plan.part.label] = _records(plan, result)
        with lock:
            state.running -= plan.part.label in started
            finished.add(plan.part.label)
            state.done += 1
            state.failed += any(r.exit for r in records[plan.part.label])
            if progress:
                progress(state)
    client.unsubscribe_topic(EVENT_TOPIC)
    final = _attempts(client, token)
    return {name: _with_attempts(recs, final) for name, recs in records.items()}


def queue_size(part: BatchPart) -> int:
    """A part's place in the queue, largest first: its STEP file's bytes times its
    operations, a proxy for its time, so that no long part starts last and leaves the
    other workers idle (Dask runs higher priorities first). 0 for a missing file (its
    task fails with its own message)."""
    try:
        n = os.path.getsize(part.path)
    except OSError:
        n = 0
    return n * max(len(part.operations), 1)


def _attempts(client: Client, token: str) -> dict[str, list[dict]]:
    """Every start event of the batch ``token``'s parts, by part name, in order."""
    starts: dict[str, list[dict]] = {}
    for _, msg in client.get_events(EVENT_TOPIC):
        if msg.get("batch") == token:
            starts.setdefault(msg["part"], []).append(msg)
    return starts


def _with_attempts(records: list[Record], starts: dict[str, list[dict]]) -> list[Record]:
    """The records with their attempts counted from every start event, and the workers
    that died running the part named."""
    for r in records:
        events = starts.get(r.part, [])
        if len(events) > 1:
            r.attempts = len(events)
            r.message = _retried(events) + r.message
    return records


def _retried(events: list[dict]) -> str:
    lost = ", ".join(f"{e['worker']} (pid {e['pid']} on {e['host']})" for e in events[:-1])
    return f"retried after worker {lost} died running it; "


def _records(plan: _Planned, result: PartResult | str) -> list[Record]:
    """Write the outputs of every operation that may write them; its records."""
    if isinstance(result, str):
        return [Record.of(plan.part.label, OperationResult(op.label, EXIT_INTERNAL,
                                                           message=result), "", 1, [])
                for op in plan.part.operations]
    (plan.folder / STATE).unlink(missing_ok=True)   # outputs change: the old hash goes
    records = []
    for op_result, outputs in zip(result.operations, plan.sets):
        written = []
        if op_result.contents:
            try:
                outputs.write({d: op_result.contents[d.name] for d in outputs.destinations})
                written = [str(d.relative_to(plan.folder.parent)) for d in outputs.destinations]
            except OutputError as e:
                op_result.exit, op_result.message = e.exit_code, str(e)
        records.append(Record.of(plan.part.label, op_result, f"{result.host}:{result.pid}",
                                 1, written))
    if all(r.outputs for r in records):   # a re-run may skip the part only if all are there
        save_state(plan.folder, plan.digest, records)
    return records
