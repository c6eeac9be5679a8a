"""A batch's unit of work: one part and its operations, run by :func:`run_part` in one
process (a Dask worker, or the caller's). Parts travel as paths (OCCT shapes do not
pickle); the outputs travel back as bytes, and the caller writes them
(:mod:`cadcnc.batch.engine`), so the workers need to see the parts but not the output
folder.
"""

from __future__ import annotations

import os
import socket
import time
from dataclasses import dataclass, field

from distributed import get_worker

from ..core.errors import EXIT_INTERNAL, EXIT_OK, CadcncError
from ..core.job import Job
from ..pipeline.operate import Settings, operate, rendered

EVENT_TOPIC = "cadcnc-batch"
"""The Dask event topic on which a task says it started (part, worker, pid, host)."""


@dataclass(frozen=True)
class BatchOperation:
    """One operation of a batch part: ``command`` ("path", "pencil", "finish": its name in
    messages), its ``job`` (whose ``source`` is the part's path), ``settings``, the output
    file ``names`` (in the part's folder; the suffix picks the format), and ``name``, the
    operation's name in the summary (default: the command)."""

    command: str
    job: Job
    outputs: tuple[str, ...] = ("program.json",)
    settings: Settings = Settings()
    name: str = ""

    @property
    def label(self) -> str:
        return self.name or self.command


@dataclass(frozen=True)
class BatchPart:
    """A part of a batch: its STEP ``path``, its ``name`` (its folder under the batch's
    output folder; default: the file's stem) and its ``operations``, run in order."""

    path: str
    operations: tuple[BatchOperation, ...]
    name: str = ""

    @property
    def label(self) -> str:
        return self.name or os.path.splitext(os.path.basename(self.path))[0]


@dataclass
class OperationResult:
    """One operation's result from a worker: exit code, cuts, coverage (the share of what
    the operation found, corners, stretches or passes, that it cut; nan when nothing was
    found), seconds (computing and gating; ``cpu_seconds`` the process's CPU time over
    them), message, and ``contents`` ({file name: bytes or str}, empty when the verdict
    writes nothing)."""

    operation: str
    exit: int
    cuts: int = 0
    coverage: float = float("nan")
    seconds: float = 0.0
    message: str = ""
    contents: dict = field(default_factory=dict)
    cpu_seconds: float = 0.0


@dataclass
class PartResult:
    """What :func:`run_part` returns: the part's name, the worker that ran it (host, pid)
    and one :class:`OperationResult` per operation."""

    part: str
    host: str
    pid: int
    operations: list[OperationResult]


def _announce(part: str, batch: str) -> None:
    """Log the task's start on the Dask event topic, with the ``batch``'s token (nothing
    outside a Dask worker)."""
    try:
        worker = get_worker()
    except ValueError:   # not in a Dask worker
        return
    worker.log_event(EVENT_TOPIC, {"batch": batch, "part": part, "worker": worker.address,
                                   "pid": os.getpid(), "host": socket.gethostname()})


def run_operation(path: str, op: BatchOperation) -> OperationResult:
    """One operation on ``path``; the library's errors become the result's exit code and
    message, any other exception exit 1 (an internal error), so that one failing part
    never stops the batch."""
    t0, cpu0 = time.monotonic(), time.process_time()
    try:
        done = operate(path, op.job, op.command, op.settings)
    except CadcncError as e:
        return OperationResult(op.label, e.exit_code, seconds=time.monotonic() - t0,
                               message=str(e), cpu_seconds=time.process_time() - cpu0)
    except Exception as e:  # noqa: BLE001 - a bug in one part must not end the batch
        return OperationResult(op.label, EXIT_INTERNAL, seconds=time.monotonic() - t0,
                               message=f"internal error: {type(e).__name__}: {e}",
                               cpu_seconds=time.process_time() - cpu0)
    cpu = time.process_time() - cpu0
    program, verdict = done.program, done.verdict
    found = len(program.cuts) + len(program.skipped)
    message = "; ".join(verdict.messages) or ("" if verdict.code == EXIT_OK else
                                                f"exit {verdict.code}")
    contents = rendered(done, op.outputs, op.command, op.settings) if verdict.write else {}
    return OperationResult(op.label, verdict.code, len(program.cuts),
                           len(program.cuts) / found if found else float("nan"),
                           done.seconds_computed + done.seconds_gated, message, contents,
                           cpu)


def run_part(part: BatchPart, batch: str = "") -> PartResult:
    """Every operation of ``part``, in order, in this process (the batch's one task);
    ``batch``: the token of the batch, on the start event."""
    _announce(part.label, batch)
    return PartResult(part.label, socket.gethostname(), os.getpid(),
                      [run_operation(part.path, op) for op in part.operations])
