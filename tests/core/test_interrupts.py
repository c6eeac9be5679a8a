"""An interrupt that lands in Python code called back from C (numba's compiler writing its
cache) is delivered again once that code has returned, not printed and dropped."""

import signal
import sys
import time

import pytest

from cadcnc.core.interrupts import REDELIVER_S, interrupt


def _frame_in(filename: str):
    """A live frame whose code comes from ``filename``."""
    scope: dict = {}
    exec(compile("import sys\ndef here():\n    return sys._getframe()\n", filename, "exec"),
         scope)
    return scope["here"]()


def test_an_interrupt_outside_a_callback_raises():
    with pytest.raises(KeyboardInterrupt):
        interrupt(signal.SIGINT, sys._getframe())


def test_an_interrupt_inside_a_callback_is_sent_again():
    got = []
    previous = signal.signal(signal.SIGUSR1, lambda signum, frame: got.append(signum))
    try:
        interrupt(signal.SIGUSR1, _frame_in("/x/site-packages/llvmlite/binding/fake.py"))
        deadline = time.monotonic() + 100 * REDELIVER_S
        while not got and time.monotonic() < deadline:
            time.sleep(REDELIVER_S / 4)
    finally:
        signal.signal(signal.SIGUSR1, previous)
    assert got == [signal.SIGUSR1]
