"""SIGTERM handled as Ctrl-C: a command that makes temporary files or starts processes
cleans up after ``kill PID`` as after Ctrl-C (exit 130), and the renames of an output set
finish before either signal is acted on."""

from __future__ import annotations

import contextlib
import signal
import threading

from .interrupts import sigint_deferred


def _interrupt(signum, frame):
    raise KeyboardInterrupt


@contextlib.contextmanager
def sigterm_as_interrupt():
    """While the block runs, SIGTERM raises KeyboardInterrupt in the main thread (the
    ``finally`` blocks and ``except KeyboardInterrupt`` of Ctrl-C then run)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextlib.contextmanager
def signals_deferred():
    """Hold Ctrl-C and SIGTERM until the block is done, then raise KeyboardInterrupt."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: caught.append(signum))
    try:
        with sigint_deferred():
            yield
    finally:
        signal.signal(signal.SIGTERM, previous)
    if caught:
        raise KeyboardInterrupt
