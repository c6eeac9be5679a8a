"""A batch's records: one :class:`Record` per part and operation, the job hash that lets a
re-run skip an unchanged part, the summary files (CSV and JSON) and the batch's exit code.

Exit code of a batch (docs/reliability.md): the pipeline's rule across parts
(:func:`cadcnc.pipeline.exit_policy.across_parts`).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
from dataclasses import asdict, dataclass, field, fields
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from ..core.errors import EXIT_OK, InputError
from ..core.jsonable import plain
from ..io.atomic import write_text
from ..pipeline.exit_policy import across_parts
from .task import BatchPart, OperationResult

STATE = "batch-part.json"
"""The file in each part's folder that records its job hash and its records."""
SUMMARY = "summary"
"""The summary's file stem in the batch's output folder (summary.csv, summary.json)."""
DONE, FAILED, SKIPPED = "done", "failed", "skipped"


@dataclass
class Record:
    """One part's one operation in the summary. ``status``: "done" (exit 0), "failed"
    (any other exit code) or "skipped" (unchanged since a run that wrote its outputs; the
    other fields are that run's); ``coverage``: the share of the corners, stretches or
    passes the operation found that it cut; ``seconds``: computing and gating;
    ``attempts``: how many times a worker started the part (2 or more: a worker died
    while running it and Dask ran it again); ``worker``: host:pid of the run that counts;
    ``outputs``: the files written, relative to the batch's output folder;
    ``cpu_seconds``: the worker's CPU time over ``seconds`` (less when it shared a core)."""

    part: str
    operation: str
    status: str
    exit: int
    cuts: int = 0
    coverage: float = math.nan
    seconds: float = 0.0
    message: str = ""
    attempts: int = 1
    worker: str = ""
    outputs: list[str] = field(default_factory=list)
    cpu_seconds: float = 0.0

    @classmethod
    def of(cls, part: str, result: OperationResult, worker: str, attempts: int,
           outputs: list[str]) -> "Record":
        return cls(part, result.operation, DONE if result.exit == EXIT_OK else FAILED,
                   result.exit, result.cuts, result.coverage, result.seconds,
                   result.message, attempts, worker, outputs, result.cpu_seconds)


COLUMNS = [f.name for f in fields(Record)]


def version_of_cadcnc() -> str:
    try:
        return version("cadcnc")
    except PackageNotFoundError:  # a source tree that is not installed
        return "unknown"


def job_hash(part: BatchPart) -> str:
    """SHA-256 of what a part's outputs depend on: the part file's bytes, every operation
    (its command, name, Job, settings and output names) and cadcnc's version."""
    try:
        data = Path(part.path).read_bytes()
    except OSError as e:
        raise InputError(f"{part.path}: cannot read the part ({e.strerror or e})") from e
    h = hashlib.sha256(hashlib.sha256(data).digest())
    for op in part.operations:
        h.update(repr((op.command, op.label, op.job, op.settings, op.outputs)).encode())
    h.update(version_of_cadcnc().encode())
    return h.hexdigest()


def unchanged(folder: Path, digest: str, outputs: list[str]) -> list[Record] | None:
    """The records of the last run in ``folder`` when it had the hash ``digest`` and every
    output it names exists (the part may be skipped), else None."""
    try:
        state = json.loads((folder / STATE).read_text())
        if state.get("hash") != digest:
            return None
        records = [Record(**{**r, "coverage": _number(r["coverage"]), "status": SKIPPED})
                   for r in state["records"]]
    except (OSError, ValueError, TypeError, KeyError):
        return None
    ok = all((folder / name).is_file() for name in outputs)
    return records if ok else None


def _number(x) -> float:
    return math.nan if x is None else float(x)


def save_state(folder: Path, digest: str, records: list[Record]) -> None:
    """Record ``digest`` and ``records`` in the part's folder (written last, atomically)."""
    write_text(folder / STATE, json.dumps({"hash": digest, "records": [
        plain(asdict(r)) for r in records]}, indent=1))


def batch_exit(records: list[Record]) -> int:
    """The batch's exit code (module doc): the pipeline's rule across parts."""
    return across_parts(r.exit for r in records)


def summary_csv(records: list[Record]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(COLUMNS)
    for r in records:
        row = asdict(r)
        row["outputs"] = " ".join(r.outputs)
        w.writerow([row[c] for c in COLUMNS])
    return buf.getvalue()


def summary_json(records: list[Record]) -> str:
    return json.dumps({"format": "cadcnc-batch-summary", "version": 1,
                       "cadcnc": version_of_cadcnc(), "exit": batch_exit(records),
                       "records": [plain(asdict(r)) for r in records]}, indent=1)


def write_summary(out: Path, records: list[Record]) -> list[Path]:
    """summary.csv and summary.json in the batch's output folder; their paths."""
    paths = [out / f"{SUMMARY}.csv", out / f"{SUMMARY}.json"]
    write_text(paths[0], summary_csv(records))
    write_text(paths[1], summary_json(records))
    return paths


def summary_table(records: list[Record]) -> str:
    """The summary as a text table: part, operation, status, exit, cuts, coverage,
    seconds, attempts, message."""
    rows = [("part", "operation", "status", "exit", "cuts", "coverage", "time", "tries",
             "message")]
    for r in records:
        cover = "-" if math.isnan(r.coverage) else f"{r.coverage:.0%}"
        rows.append((r.part, r.operation, r.status, str(r.exit), str(r.cuts), cover,
                     f"{r.seconds:.1f} s", str(r.attempts), r.message.splitlines()[0]
                     if r.message else ""))
    widths = [max(len(row[k]) for row in rows) for k in range(len(rows[0]) - 1)]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(row, widths)) + "  " + row[-1]
                     for row in rows)
