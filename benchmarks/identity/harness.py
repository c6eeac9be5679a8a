"""Run identity cases with the ``cadcnc`` command line and digest what they write.

A :class:`Case` is a part and a list of ``cadcnc`` commands. :func:`run_case` copies the
part into an empty folder, runs each command there as a fresh process
(``python -m cadcnc.cli``; the part is named by its bare file name, so a program's
``source`` holds no folder), then records the exit code of every command and the SHA-256
of every file the commands wrote. :func:`compare` says, per file, what differs from a
recorded result. The standard library only (no cadcnc import): the same harness can check
a checkout before and after a change (``python=`` another tree's interpreter).
"""

from __future__ import annotations

import hashlib
import json
import os
import resource
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

FORMAT = "cadcnc-identity-digests"
VERSION = 1
# batch writes these keys per record: they vary from run to run (timings, the worker's
# host:pid), so they are dropped before digesting summary.json (see NORMALISERS)
BATCH_VARYING_KEYS = ("seconds", "cpu_seconds", "worker")
# the operations whose work is spread over processes: always run at --jobs 1
JOBS_COMMANDS = ("path", "pencil", "finish")


@dataclass(frozen=True)
class Case:
    """One identity case: ``commands`` (argv lists after ``cadcnc``; ``{part}`` is the
    part's file name) run one after the other in a folder holding a copy of ``part`` (a
    path relative to the base folder given to :func:`run_case`) and ``files`` (name ->
    text, written first). Every file the commands write is digested, except ``ignore``
    (names relative to the folder); ``normalise`` maps a written file to a normaliser of
    :data:`NORMALISERS` applied before digesting."""

    name: str
    part: str
    commands: tuple[tuple[str, ...], ...]
    files: tuple[tuple[str, str], ...] = ()
    ignore: tuple[str, ...] = ()
    normalise: tuple[tuple[str, str], ...] = ()
    exits: tuple[int, ...] | None = None   # expected exit codes (default: all 0)

    def argvs(self, jobs: int = 1) -> list[list[str]]:
        """The command lines as run: ``{part}`` filled in, ``--jobs N`` (1) added to the
        operations that take it, ``-q`` to all."""
        name = Path(self.part).name
        out = []
        for command in self.commands:
            argv = [a.replace("{part}", name) for a in command]
            if argv[0] in JOBS_COMMANDS and "--jobs" not in argv:
                argv += ["--jobs", str(jobs)]
            if "-q" not in argv:
                argv.append("-q")
            out.append(argv)
        return out


@dataclass
class Result:
    """What a case wrote: exit code per command, SHA-256 per file (sorted names,
    relative to the case's folder, ``/``-separated), and the CPU seconds it took (the
    commands' processes and their children; not compared)."""

    name: str
    argv: list[list[str]]
    exits: list[int]
    files: dict[str, str]
    normalised: dict[str, str] = field(default_factory=dict)
    cpu_s: float = 0.0
    wall_s: float = 0.0
    stderr: list[str] = field(default_factory=list)

    def commands(self) -> list[str]:
        """The command lines, ``cadcnc`` and the arguments quoted as a shell would."""
        return [shlex.join(["cadcnc", *argv]) for argv in self.argv]

    def record(self) -> dict:
        out = {"commands": self.commands(), "exits": self.exits, "files": self.files}
        if self.normalised:
            out["normalised"] = self.normalised
        out["cpu_s"] = round(self.cpu_s, 1)
        return out


def _drop_batch_varying(data: bytes, folder: Path) -> bytes:
    """summary.json of ``cadcnc batch`` without its per-record timings and worker names
    and without the version of cadcnc (``"cadcnc"``)."""
    doc = json.loads(data)
    doc.pop("cadcnc", None)
    for record in doc.get("records", []):
        for key in BATCH_VARYING_KEYS:
            record.pop(key, None)
    return json.dumps(doc, indent=1, sort_keys=True).encode()


def _drop_folder(data: bytes, folder: Path) -> bytes:
    """Every occurrence of the case's folder's absolute path and its ``/`` removed (batch
    writes the part's absolute path as the program's ``source``)."""
    for form in {str(folder), os.path.realpath(folder)}:
        data = data.replace(form.encode() + b"/", b"")
    return data


NORMALISERS = {
    "batch-summary": (_drop_batch_varying,
                      "per-record 'seconds', 'cpu_seconds', 'worker' and the top-level "
                      "'cadcnc' version dropped; re-serialised with sorted keys"),
    "folder": (_drop_folder, "the run folder's absolute path + '/' removed"),
}


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _written(folder: Path, before: set[str]) -> list[str]:
    names = []
    for path in folder.rglob("*"):
        if path.is_file():
            rel = path.relative_to(folder).as_posix()
            if rel not in before:
                names.append(rel)
    return sorted(names)


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_case(case: Case, base: Path, *, python: str | None = None, keep: Path | None = None,
             timeout: float | None = None, jobs: int = 1) -> Result:
    """Run ``case`` with its part from ``base`` in a fresh folder (kept under ``keep`` if
    given) and digest its outputs. ``python``: the interpreter that runs
    ``-m cadcnc.cli`` (default this one); ``jobs``: ``--jobs`` of the operations (the
    record is made at 1; the outputs are meant to be the same bytes at any N)."""
    python = python or sys.executable
    if keep is not None:
        folder = Path(keep) / case.name
        if folder.exists():
            shutil.rmtree(folder)
        folder.mkdir(parents=True)
        tmp = None
    else:
        tmp = tempfile.TemporaryDirectory(prefix=f"identity-{case.name}-")
        folder = Path(tmp.name)
    folder = folder.resolve()
    try:
        shutil.copyfile(Path(base) / case.part, folder / Path(case.part).name)
        for name, text in case.files:
            (folder / name).write_text(text)
        before = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}
        env = {**os.environ, "CADCNC_JOBS": str(jobs)}
        exits, errors = [], []
        cpu0, wall0 = _children_cpu(), time.perf_counter()
        argvs = case.argvs(jobs)
        for argv in argvs:
            proc = subprocess.run([python, "-m", "cadcnc.cli", *argv], cwd=folder, env=env,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                  timeout=timeout)
            exits.append(proc.returncode)
            errors.append(proc.stderr[-2000:])
        cpu, wall = _children_cpu() - cpu0, time.perf_counter() - wall0
        files, normalised = digest_outputs(case, folder, _written(folder, before))
        return Result(case.name, argvs, exits, files, normalised, cpu, wall, errors)
    finally:
        if tmp is not None:
            tmp.cleanup()


def digest_outputs(case: Case, folder: Path, names: list[str]) -> tuple[dict, dict]:
    """({name: SHA-256}, {name: what was normalised}) of the files ``names`` of ``folder``
    (relative), less the case's ``ignore``, after its ``normalise`` rules."""
    rules = dict(case.normalise)
    files, normalised = {}, {}
    for name in sorted(names):
        if name in case.ignore:
            continue
        data = (Path(folder) / name).read_bytes()
        if name in rules:
            fn, what = NORMALISERS[rules[name]]
            data = fn(data, Path(folder))
            normalised[name] = what
        files[name] = sha256(data)
    return files, normalised


def expected_exits(case: Case) -> list[int]:
    return list(case.exits) if case.exits is not None else [0] * len(case.commands)


def compare(expected: dict, result: Result) -> list[str]:
    """Differences between a recorded case (a :meth:`Result.record`) and a new result,
    one line each naming the case and the file; empty when identical. ``cpu_s`` is not
    compared."""
    name = result.name
    out = []
    if expected.get("commands") != result.commands():
        out.append(f"{name}: the command lines differ from the recorded ones "
                   f"(recorded {expected.get('commands')}, now {result.commands()}): "
                   f"re-record")
    if expected.get("exits") != result.exits:
        out.append(f"{name}: exit codes {result.exits}, recorded {expected.get('exits')}")
    old, new = expected.get("files", {}), result.files
    for f in sorted(set(old) | set(new)):
        if f not in new:
            out.append(f"{name}: {f}: recorded but not written now")
        elif f not in old:
            out.append(f"{name}: {f}: written now but not recorded")
        elif old[f] != new[f]:
            out.append(f"{name}: {f}: CHANGED (sha256 {new[f][:16]}..., recorded "
                       f"{old[f][:16]}...)")
    if expected.get("normalised", {}) != result.normalised:
        out.append(f"{name}: normalisation differs from the recorded one")
    return out


def read_digests(path: Path) -> dict:
    doc = json.loads(Path(path).read_text())
    if doc.get("format") != FORMAT or doc.get("version") != VERSION:
        raise ValueError(f"{path}: not a {FORMAT} file of version {VERSION}")
    return doc


CODE_PATHS = ("cadcnc", "cli", "pyproject.toml")   # what the commands run (not the tests)


def git_commit() -> str:
    """The last commit that changed the package's code (:data:`CODE_PATHS` that exist),
    ``+dirty`` when they have uncommitted changes: the code a record was made with."""
    root = Path(__file__).resolve().parents[2]
    paths = [p for p in CODE_PATHS if (root / p).exists()]
    try:
        head = subprocess.run(["git", "log", "-1", "--format=%h", "--", *paths], cwd=root,
                              text=True, capture_output=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no",
                                "--", *paths], cwd=root, text=True,
                               capture_output=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return (head or "unknown") + ("+dirty" if dirty else "")
