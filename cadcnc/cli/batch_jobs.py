"""A job file's parts and operations as the library's batch records: each operation's
options (shared, the operation's, the part's) parsed by its own command's parser, as
``cadcnc COMMAND PART --key value ... -o NAME.SUFFIX``, into its Job and Settings, so a job
file takes exactly the command line's options; a mistake is named by its line and key.
"""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

from cadcnc.batch.task import BatchOperation, BatchPart
from cadcnc.core.errors import InputError
from cadcnc.io.outputs import SUFFIXES

from .options import BUILDERS, settings_of

CLI_ONLY = ("output", "stream", "machine", "jerk", "quiet", "debug", "help", "step", "jobs")
"""Options a job file does not take: the outputs are the job file's own ``outputs``, and
each part runs in one process (``--jobs 1``)."""


def batch_parts(job, parser) -> list:
    """Every part's :class:`~cadcnc.batch.task.BatchPart`: its operations' options (shared,
    the operation's, the part's) parsed by the command's parser (``parser``: the
    ``cadcnc`` parser) into Jobs."""
    for k, suffix in enumerate(job.outputs):
        if suffix not in SUFFIXES:
            raise job.error(("outputs", k), f"{suffix!r}: the outputs are "
                                            f"{', '.join(SUFFIXES)}")
    stems: dict[str, str] = {}
    for path in job.parts:   # each part's folder is its file's stem
        other = stems.setdefault(Path(path).stem, path)
        if other != path:
            raise job.error(("parts",), f"{other} and {path} would share the output folder "
                                        f"{Path(path).stem!r}: rename one")
    parts = []
    for path in job.parts:
        ops = []
        for op in job.operations:
            if op.parts is not None and path not in op.parts:
                continue
            options = {**job.options, **op.options, **job.per_part.get(Path(path).name, {})}
            names = tuple(op.name + s for s in job.outputs)
            built, settings = operation_of(job, parser, op, path, options, names)
            ops.append(BatchOperation(op.command, built, names, settings, op.name))
        if not ops:
            raise job.error(("parts",), f"{path}: no operation applies to this part")
        parts.append(BatchPart(path, tuple(ops)))
    return parts


def operation_of(job, parser, op, path: str, options: dict, outputs: tuple):
    """(Job, Settings) of one operation on ``path``: ``options`` ({key: (value, where)})
    parsed by the command's own parser, as ``cadcnc COMMAND PATH --key value ... -o ...``."""
    if op.command not in BUILDERS:
        raise job.error(op.where + ("command",), f"{op.command!r}: the commands are "
                                                  f"{', '.join(BUILDERS)}")
    argv = [op.command, path]
    for key, (value, where) in options.items():
        if key in CLI_ONLY:
            raise job.error(where, "not an option of a job file (outputs: the job file's "
                                   "`outputs`)")
        argv += _words(job, key, value, where)
    for name in outputs:
        argv += ["-o", name]
    args = _parse(job, parser, argv, options, op.where)
    for key, (_, where) in options.items():
        if not hasattr(args, key.replace("-", "_")):   # an abbreviation argparse accepted
            raise job.error(where, f"unknown option of `cadcnc {op.command}`")
    try:
        return BUILDERS[op.command](args, path), settings_of(args, processes=1)  # one a part
    except InputError as e:
        raise job.error(_where_named(str(e), options, op.where), str(e)) from None


def _words(job, key: str, value, where: tuple) -> list[str]:
    """``--key value`` of a job file's value: true a flag, false nothing, a list its
    items; numbers and strings as written."""
    if isinstance(value, bool):
        return [f"--{key}"] if value else []
    if isinstance(value, list) and all(isinstance(v, (int, float, str)) and
                                       not isinstance(v, bool) for v in value):
        return [f"--{key}", *map(str, value)]
    if isinstance(value, (int, float, str)):
        return [f"--{key}={value}"]
    raise job.error(where, f"a number, a string, true/false or a list of them, got {value!r}")


def _parse(job, parser, argv: list[str], options: dict, where: tuple):
    """The command's namespace, or the parser's complaint as a job file error on the line
    of the option it names."""
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            return parser.parse_args(argv)
    except SystemExit:
        said = err.getvalue().strip().splitlines()
        message = said[-1].split("error: ", 1)[-1] if said else "not understood"
        raise job.error(_where_named(message, options, where), message) from None


def _where_named(message: str, options: dict, where: tuple) -> tuple:
    """The key path of the first option ``message`` names (``--radius``, "radius"), else
    ``where``."""
    for key, (_, at) in options.items():
        if re.search(rf"(--|\b){re.escape(key)}\b|\b{re.escape(key.replace('-', ' '))}\b",
                     message):
            return at
    return where
