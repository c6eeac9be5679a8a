"""Ctrl-C (SIGINT), and SIGTERM where asked, held back while a block must finish: renames of an output set, the
first import of the geometry kernel (an interrupted C-extension import turns into an
ImportError instead of a KeyboardInterrupt)."""

from __future__ import annotations

import contextlib
import signal
import threading


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
