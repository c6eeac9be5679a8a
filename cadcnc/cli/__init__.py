"""cadcnc's command line (installed as the ``cadcnc`` console script)."""

from __future__ import annotations

import os
import sys

from cadcnc.core.errors import EXIT_INTERRUPTED
from cadcnc.core.interrupts import ctrl_c_interrupts

from .commands import load


def main(argv: list[str] | None = None) -> int:
    """Run the command line; Ctrl-C while it starts up is exit 130 too, not a traceback.

    Called as the program (``argv`` None: the console script, ``python -m cadcnc.cli``),
    the process ends here with :func:`os._exit` once the output is flushed. Python's own
    teardown would first reset SIGINT to the system default and then spend about 0.7 s
    freeing OCCT and numba objects: a Ctrl-C in that window killed the finished process by
    the signal (exit -2) instead of leaving its exit code.
    """
    ctrl_c_interrupts()   # not lost inside numba's compiler callbacks
    try:
        code = load("cadcnc.cli.app:main")(argv, ending=argv is None)   # Ctrl-C caught
    except KeyboardInterrupt:  # during start-up or argument parsing
        print("cadcnc: interrupted", file=sys.stderr)
        code = EXIT_INTERRUPTED
    if argv is None:
        _exit_now(code)
    return code


def _exit_now(code: int) -> None:
    """Flush stdout and stderr, then end the process with ``code`` at once."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (BrokenPipeError, OSError, ValueError):  # the reader left: nothing to say
            pass
    os._exit(code)


__all__ = ["main"]
