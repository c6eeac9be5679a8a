"""A batch job file (TOML or JSON, docs/batch.md) read and checked, with the line of every
key, so that a mistake is refused before any work as ``FILE:LINE: KEY: what is wrong``.

Top-level keys: ``parts`` (paths or glob patterns, relative to the file), ``operations``
(tables: ``command``, optional ``name`` and ``parts``, and the command's options),
``options`` (every operation's), ``per_part`` (options by part file name), ``out`` and
``outputs``. The options themselves are checked by the command's own parser
(:mod:`cadcnc.cli.batch_jobs`).
"""

from __future__ import annotations

import glob
import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import tomllib

from ..core.errors import InputError

TOP_KEYS = ("parts", "operations", "options", "per_part", "out", "outputs")
OPERATION_KEYS = ("command", "name", "parts")
DEFAULT_OUTPUTS = (".json", ".ngc")
GLOB_CHARS = re.compile(r"[*?\[]")


class JobFileError(InputError):
    """A job file's mistake, named by its line and key (exit 2)."""


@dataclass
class Operation:
    """One ``operations`` entry: its command, name, ``where`` (its key path), the parts it
    is limited to (resolved paths; None: every part) and its own options."""

    command: str
    name: str
    where: tuple
    parts: set[str] | None
    options: dict = field(default_factory=dict)


@dataclass
class JobFile:
    """A job file read: its parts (resolved paths, in order), operations, shared and
    per-part options (``{key: (value, key path)}``), output folder and suffixes; ``at``
    finds a key path's line."""

    path: Path
    parts: list[str]
    operations: list[Operation]
    options: dict
    per_part: dict
    out: Path
    outputs: tuple[str, ...]
    lines: dict

    def at(self, where: tuple) -> int:
        """The line of the key path ``where`` (its nearest recorded parent's, else 1)."""
        return next((self.lines[where[:k]] for k in range(len(where), 0, -1)
                     if where[:k] in self.lines), 1)

    def error(self, where: tuple, message: str) -> JobFileError:
        return JobFileError(f"{self.path}:{self.at(where)}: {show(where)}: {message}")


def show(where: tuple) -> str:
    """A key path as ``operations[2].radius`` (entries counted from 1)."""
    text = ""
    for k in where:
        text += f"[{k + 1}]" if isinstance(k, int) else (f".{k}" if text else str(k))
    return text


def read(path) -> JobFile:
    """The job file at ``path`` (.toml or .json), checked (JobFileError: line and key)."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as e:
        raise InputError(f"{path}: cannot read the job file ({e.strerror or e})") from None
    kind = path.suffix.lower()
    if kind not in READERS:
        raise InputError(f"{path}: a job file is .toml or .json")
    loads, error, locate = READERS[kind]
    try:
        data = loads(text)
    except error as e:   # each names the line and column
        raise JobFileError(f"{path}: not {kind[1:].upper()}: {e}") from None
    lines = locate(text)
    if not isinstance(data, dict):
        raise JobFileError(f"{path}:1: the job file must be a table of keys")
    job = JobFile(path, [], [], {}, {}, path.with_name(path.stem + "-out"), DEFAULT_OUTPUTS,
                  lines)
    _check(job, data)
    return job


def _check(job: JobFile, data: dict) -> None:
    """The keys and values of ``data``, into ``job`` (JobFileError: line and key)."""
    for key in data:
        if key not in TOP_KEYS:
            raise job.error((key,), f"unknown key; the keys are {', '.join(TOP_KEYS)}")
    for key in ("parts", "operations"):
        if key not in data:
            raise JobFileError(f"{job.path}:1: {key}: missing (docs/batch.md)")
    job.parts = _parts(job, _list(job, data, "parts", str), ("parts",))
    if "out" in data:
        job.out = job.path.parent / _string(job, data["out"], ("out",))
    if "outputs" in data:
        job.outputs = tuple(_suffix(job, s, ("outputs", k))
                            for k, s in enumerate(_list(job, data, "outputs", str)))
    job.options = _options(job, data.get("options", {}), ("options",))
    per_part = data.get("per_part", {})
    if not isinstance(per_part, dict):
        raise job.error(("per_part",), "a table of part file names")
    names = {Path(p).name for p in job.parts}
    for name, options in per_part.items():
        if name not in names:
            raise job.error(("per_part", name), "names no part of the batch (its file name)")
        job.per_part[name] = _options(job, options, ("per_part", name))
    for k, entry in enumerate(_list(job, data, "operations", dict)):
        job.operations.append(_operation(job, entry, ("operations", k)))
    seen = [op.name for op in job.operations]
    for k, name in enumerate(seen):
        if name in seen[:k]:
            raise job.error(job.operations[k].where + ("name",), f"{name!r} is the name of "
                            "an earlier operation (outputs NAME.json): give another name")


def _list(job: JobFile, data: dict, key: str, kind) -> list:
    items = data[key]
    if not isinstance(items, list) or not items or not all(isinstance(x, kind) for x in items):
        what = "strings" if kind is str else "tables"
        raise job.error((key,), f"a non-empty list of {what}")
    return items


def _string(job: JobFile, value, where: tuple) -> str:
    if not isinstance(value, str) or not value:
        raise job.error(where, f"a non-empty string, got {value!r}")
    return value


def _suffix(job: JobFile, value: str, where: tuple) -> str:
    suffix = value if value.startswith(".") else "." + value
    if not re.fullmatch(r"\.[A-Za-z0-9]+", suffix):
        raise job.error(where, f"an output suffix such as .json or .ngc, got {value!r}")
    return suffix.lower()


def _parts(job: JobFile, patterns: list[str], where: tuple) -> list[str]:
    """The part files of ``patterns`` (relative to the job file), each once, in order."""
    found: list[str] = []
    for k, pattern in enumerate(patterns):
        full = job.path.parent / pattern
        if GLOB_CHARS.search(pattern):
            matches = sorted(glob.glob(str(full)))
            if not matches:
                raise job.error(where + (k,), f"{pattern!r} matches no file")
        elif not full.is_file():
            raise job.error(where + (k,), f"missing part: {full} is not a file")
        else:
            matches = [str(full)]
        found += [str(Path(m).resolve()) for m in matches]
    return list(dict.fromkeys(found))


def _options(job: JobFile, options, where: tuple) -> dict:
    if not isinstance(options, dict):
        raise job.error(where, "a table of options (the command's long options)")
    return {key.replace("_", "-"): (value, where + (key,)) for key, value in options.items()}


def _operation(job: JobFile, entry: dict, where: tuple) -> Operation:
    if "command" not in entry:
        raise job.error(where, "command: missing (path, pencil or finish)")
    command = _string(job, entry["command"], where + ("command",))
    name = _string(job, entry.get("name", command), where + ("name",))
    if not re.fullmatch(r"[\w.-]+", name):
        raise job.error(where + ("name",), f"{name!r}: letters, digits, '.', '-', '_' only")
    chosen = None
    if "parts" in entry:
        chosen = set(_parts(job, _list(job, entry, "parts", str), where + ("parts",)))
        stray = chosen - set(job.parts)
        if stray:
            raise job.error(where + ("parts",), f"{sorted(stray)[0]} is not among the "
                                                "batch's parts")
    options = {k: v for k, v in entry.items() if k not in OPERATION_KEYS}
    return Operation(command, name, where, chosen, _options(job, options, where))


# -- lines of keys ---------------------------------------------------------------------------
def _key(text: str) -> str:
    text = text.strip()
    return text[1:-1] if len(text) > 1 and text[0] == text[-1] and text[0] in "\"'" else text


def toml_lines(text: str) -> dict:
    """{key path: line} of a TOML text's tables, keys, array entries and the keys of
    one-line inline tables (enough for the job file's layout)."""
    lines: dict = {}
    table: tuple = ()
    counts: dict = {}
    array: tuple | None = None   # the key path of a multi-line array being read
    index = 0
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if array is not None:
            for _ in re.findall(r"\"[^\"]*\"|'[^']*'|\{", line):
                lines.setdefault(array + (index,), n)
                index += 1
            if line.startswith("]"):
                array = None
            continue
        if line.startswith("[["):
            name = tuple(_key(k) for k in line.strip("[]").split("."))
            counts[name] = counts.get(name, -1) + 1
            table = name + (counts[name],)
            lines.setdefault(name, n)
            lines[table] = n
        elif line.startswith("["):
            table = tuple(_key(k) for k in re.findall(r"\"[^\"]*\"|'[^']*'|[^.]+",
                                                       line.strip("[]")))
            lines[table] = n
        elif "=" in line and not line.startswith("#"):
            key, value = line.split("=", 1)
            path = table + tuple(_key(k) for k in key.split("."))
            lines[path] = n
            value = value.strip()
            for inner in re.findall(r"[{,]\s*([\w\"'-]+)\s*=", value):
                lines[path + (_key(inner),)] = n
            if value.startswith("["):
                items = re.findall(r"\"[^\"]*\"|'[^']*'|\{", value)
                for k in range(len(items)):
                    lines[path + (k,)] = n
                if value.count("[") > value.count("]"):
                    array, index = path, len(items)
    return lines


def json_lines(text: str) -> dict:
    """{key path: line} of every key and array entry of a JSON text."""
    lines: dict = {}
    stack: list[list] = []   # [kind "{" or "[", key or index, awaiting a key]
    line, i = 1, 0

    def value_starts() -> None:
        if stack and stack[-1][0] == "[":
            lines.setdefault(tuple(s[1] for s in stack), line)

    while i < len(text):
        c = text[i]
        if c == "\n":
            line += 1
        elif c == '"':
            j = i + 1
            while text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            if stack and stack[-1][0] == "{" and stack[-1][2]:
                stack[-1][1:] = [json.loads(text[i:j + 1]), False]
                lines[tuple(s[1] for s in stack)] = line
            else:
                value_starts()
            i = j
        elif c in "{[":
            value_starts()
            stack.append([c, 0, c == "{"])
        elif c in "}]":
            stack.pop()
        elif c == "," and stack:
            if stack[-1][0] == "{":
                stack[-1][2] = True
            else:
                stack[-1][1] += 1
        elif not c.isspace() and c != ":":
            value_starts()
        i += 1
    return lines


READERS = {".json": (json.loads, json.JSONDecodeError, json_lines),
           ".toml": (tomllib.loads, tomllib.TOMLDecodeError, toml_lines)}
"""The reader, its error and the key lines of each job file format, by suffix."""
