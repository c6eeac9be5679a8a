"""The one progress callback of the package: ``progress(done, total, what)``.

Every long computation that reports its progress (an operation's corners, planes, levels
or interpolation cycles; the gate's stages; a stream's periods) calls it with ``done``
units of work finished out of ``total`` (0 when the total is not known), and ``what``, a
short phrase a user can read ("plane 3 at 12.000 mm", "verify: cuts"). It is called from
the computing thread; it returns nothing, and raising from it stops the work.
"""

from __future__ import annotations

from typing import Protocol


class Progress(Protocol):
    def __call__(self, done: int, total: int, what: str) -> None: ...


def travelled_text(mm: float) -> str:
    """The interpolator's ``what``: the distance travelled so far (mm, 3 decimals)."""
    return f"{mm:.3f} mm"
