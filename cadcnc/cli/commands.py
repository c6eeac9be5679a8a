"""The command table: each command's handler, imported when the command runs.

This is the command line's one lazy import (:func:`load`; :func:`cadcnc.cli.main` loads
the parser with it too, so that Ctrl-C while it loads is exit 130, not a traceback).
Importing the library (OCCT ~1.5 s, numba, Dask ~3 s) is paid only by a command that
needs it: ``--help`` and usage errors pay none, ``cadcnc faces`` only the part's modules
(not numba, not the interpolation core). Every handler takes the argparse namespace and
returns the exit code.
"""

from __future__ import annotations

import importlib
from typing import Callable

HANDLERS = {
    "faces": "cadcnc.cli.faces:faces",
    "path": "cadcnc.cli.operation_commands:path",
    "pencil": "cadcnc.cli.operation_commands:pencil",
    "finish": "cadcnc.cli.operation_commands:finish",
    "stream": "cadcnc.cli.stream_command:stream",
    "batch": "cadcnc.cli.batch_command:batch",
    "run": "cadcnc.cli.apt_command:run",
    "demo": "cadcnc.cli.demo_command:demo",
    "plot": "cadcnc.cli.program_commands:plot",
    "verify": "cadcnc.cli.program_commands:verify",
    "simulate": "cadcnc.cli.simulate_command:simulate",
}
"""``{command: "module:function"}`` of every command's handler."""


def load(target: str) -> Callable:
    """The function named by ``"module:function"``, its module imported now."""
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def handler(command: str) -> Callable:
    """The handler of ``command``, its module imported now."""
    return load(HANDLERS[command])
