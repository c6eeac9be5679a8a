"""Work is estimated and bounded before it starts, and long work is never silent.

Every operation estimates what it is about to do (interpolation cycles, guide planes, face
samples, points to verify) and refuses, with the estimate and the option that brings it
down, whatever exceeds its limit (:func:`refuse_over`, an :class:`WorkLimitError`: exit 2,
the input asks for too much). The limits are documented in docs/reliability.md. Long
stages call a :class:`Heartbeat`, which reports at least every ``every`` seconds (or run
inside a :class:`Ticker`, a heartbeat from a thread). A command that makes temporary files
or starts processes runs inside :func:`sigterm_as_interrupt`: ``kill PID`` cleans up as
Ctrl-C does (exit 130).
"""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from typing import Callable

from .errors import InputError
from .interrupts import interrupt

MAX_CYCLES = 5_000_000
"""Interpolation cycles one command may run in all (``--max-cycles``): about 500 m of path
at the default 0.1 mm step, some minutes of computation."""
MAX_PLANES = 20_000
"""Guide planes of one finishing job (``--max-cycles`` does not cover them: spacing)."""
MAX_VERIFY_POINTS = 2_000_000
"""Program points ``verify`` checks against OCCT in one run."""
MAX_STREAM_PERIODS = 20_000_000
"""Servo periods one stream may hold (``cadcnc stream --max-periods``): 5.6 h at 1 ms.
Its memory does not grow with them (the positions in a scratch file of 24 bytes a
period, 480 MB for this many; each .npy as large, each .txt about 40 bytes a period)."""
HEARTBEAT_S = 5.0
"""Longest silence (s) of a long stage: progress is reported at least this often."""


class WorkLimitError(InputError):
    """The input asks for more work than the limit (names the estimate and the option)."""


def refuse_over(what: str, estimate: float, limit: float, unit: str, remedy: str) -> None:
    """WorkLimitError when ``estimate`` exceeds ``limit``: "``what`` needs about N
    ``unit``, over the limit L: ``remedy``"."""
    if not estimate <= limit:   # NaN refuses too
        raise WorkLimitError(f"{what} needs about {estimate:.3g} {unit}, over the limit of "
                             f"{limit:g}: {remedy}")


class Heartbeat:
    """``beat(text)`` forwards ``text`` to ``report`` when ``every`` seconds have passed
    since the last report (``force=True``: always); ``clock`` is injectable for tests."""

    def __init__(self, report: Callable[[str], None] | None, every: float = HEARTBEAT_S,
                 clock: Callable[[], float] = time.monotonic):
        self.report, self.every, self.clock = report, every, clock
        self.last = clock()

    def beat(self, text: str | Callable[[], str], force: bool = False) -> bool:
        """Report ``text`` (or ``text()``, built only when due) if due; whether it did."""
        if self.report is None:
            return False
        now = self.clock()
        if not force and now - self.last < self.every:
            return False
        self.last = now
        self.report(text() if callable(text) else text)
        return True


class Ticker:
    """A heartbeat from a thread, for a stage that cannot report itself (a compiled loop):
    while the ``with`` block runs, ``report(f"{label}: {stage}, N s")`` at least every
    ``every`` seconds; set :attr:`stage` to say what runs. ``report`` None: silent."""

    def __init__(self, report: Callable[[str], None] | None, label: str,
                 every: float = 0.9 * HEARTBEAT_S,   # scheduling delays stay within 5 s
                 clock: Callable[[], float] = time.monotonic):
        self.report, self.label, self.every, self.clock = report, label, every, clock
        self.stage = "working"
        self._done = threading.Event()
        self._thread: threading.Thread | None = None

    def _run(self) -> None:
        start = self.clock()
        while not self._done.wait(self.every):
            self.report(f"{self.label}: {self.stage}, {self.clock() - start:.0f} s")

    def __enter__(self) -> "Ticker":
        if self.report is not None:
            self._thread = threading.Thread(target=self._run, daemon=True,
                                            name="cadcnc-heartbeat")
            self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._done.set()
        if self._thread is not None:
            self._thread.join()


@contextlib.contextmanager
def sigterm_as_interrupt():
    """While the block runs, SIGTERM raises KeyboardInterrupt in the main thread (the
    ``finally`` blocks and ``except KeyboardInterrupt`` of Ctrl-C then run)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
