"""Ctrl-C (SIGINT), and SIGTERM where asked, held back while a block must finish: renames of an output set, the
first import of the geometry kernel (an interrupted C-extension import turns into an
ImportError instead of a KeyboardInterrupt)."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from types import FrameType

CALLBACK_CODE = ("llvmlite",)
"""Python code that C calls back through ctypes (numba's compiler writing its cache): an
exception raised there is printed as "Exception ignored" and dropped, so an interrupt that
lands in it would be lost and leave a traceback on stderr."""

REDELIVER_S = 0.02
"""How soon (s) an interrupt that landed in a callback is delivered again."""


def _in_callback(frame: FrameType | None) -> bool:
    """Whether the interrupted Python code runs inside a C callback (:data:`CALLBACK_CODE`)."""
    while frame is not None:
        if any(name in frame.f_code.co_filename for name in CALLBACK_CODE):
            return True
        frame = frame.f_back
    return False


def interrupt(signum: int, frame: FrameType | None) -> None:
    """A signal handler: raise KeyboardInterrupt, or, inside a C callback where it would be
    dropped, send the same signal again :data:`REDELIVER_S` later."""
    if _in_callback(frame):
        threading.Timer(REDELIVER_S, os.kill, (os.getpid(), signum)).start()
        return
    raise KeyboardInterrupt


def ctrl_c_interrupts() -> None:
    """Make Ctrl-C raise KeyboardInterrupt through :func:`interrupt` (main thread only)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, interrupt)


@contextlib.contextmanager
def deferred(*signums: int):
    """Hold the signals ``signums`` until the block is done, then raise
    KeyboardInterrupt if one came (main thread; elsewhere the block just runs)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    previous = [signal.signal(s, lambda signum, frame: caught.append(signum))
                for s in signums]
    try:
        yield
    finally:
        for s, handler in zip(signums, previous):
            signal.signal(s, handler)
    if caught:
        raise KeyboardInterrupt


def sigint_deferred():
    """Hold Ctrl-C until the block is done, then raise KeyboardInterrupt (main thread)."""
    return deferred(signal.SIGINT)


def signals_deferred():
    """Hold Ctrl-C and SIGTERM until the block is done, then raise KeyboardInterrupt."""
    return deferred(signal.SIGINT, signal.SIGTERM)
