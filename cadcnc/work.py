"""Work is estimated and bounded before it starts, and long work is never silent.

Every operation estimates what it is about to do (interpolation cycles, guide planes, face
samples, points to verify) and refuses, with the estimate and the option that brings it
down, whatever exceeds its limit (:func:`refuse_over`, an :class:`WorkLimitError`: exit 2,
the input asks for too much). The limits are documented in docs/reliability.md. Long
stages call a :class:`Heartbeat`, which reports at least every ``every`` seconds.
"""

from __future__ import annotations

import time
from typing import Callable

from .errors import InputError

MAX_CYCLES = 5_000_000
"""Interpolation cycles one command may run in all (``--max-cycles``): about 500 m of path
at the default 0.1 mm step, some minutes of computation."""
MAX_PLANES = 20_000
"""Guide planes of one finishing job (``--max-cycles`` does not cover them: spacing)."""
MAX_VERIFY_POINTS = 2_000_000
"""Program points ``verify`` checks against OCCT in one run."""
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
