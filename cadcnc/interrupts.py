"""Ctrl-C (SIGINT) held back while a block must finish: renames of an output set, the
first import of the geometry kernel (an interrupted C-extension import turns into an
ImportError instead of a KeyboardInterrupt)."""

from __future__ import annotations

import contextlib
import signal
import threading


@contextlib.contextmanager
def sigint_deferred():
    """Hold Ctrl-C until the block is done, then raise KeyboardInterrupt (main thread)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if caught:
        raise KeyboardInterrupt
