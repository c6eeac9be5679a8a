"""``cadcnc`` run in this process, as a user runs it: exit code, stdout and stderr."""

from __future__ import annotations

import contextlib
import io
import os
from dataclasses import dataclass


@dataclass
class Run:
    """What one in-process ``cadcnc`` run left: its exit code, stdout and stderr."""
    returncode: int
    stdout: str
    stderr: str


@contextlib.contextmanager
def in_folder(path):
    """The working folder ``path`` (or the current one) for the ``with`` block."""
    old = os.getcwd()
    os.chdir(path or old)
    try:
        yield
    finally:
        os.chdir(old)


def cadcnc_cli(*args, cwd=None, check=None) -> Run:
    """Run ``cadcnc ARGS`` in this process (``cadcnc.cli.app.main``); returns its exit code,
    stdout and stderr. ``check``: the exit code it must give."""
    from cadcnc.cli.app import main

    out, err = io.StringIO(), io.StringIO()
    with in_folder(cwd), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main([str(a) for a in args])
        except SystemExit as e:  # argparse: --help, usage errors
            code = e.code
    run = Run(code, out.getvalue(), err.getvalue())
    if check is not None:
        assert run.returncode == check, (run.returncode, run.stdout, run.stderr)
    return run


BOSS_JOB = ["--faces", "4", "5", "--radius", "3", "--feed", "1500", "--period", "4ms"]
"""The boss fixture's corner (faces 4 and 5) as ``cadcnc path`` options."""
