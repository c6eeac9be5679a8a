"""The third-face and shank guard of every operation's stepper and stretch search.

:class:`~cadcnc.geometry.clearance.ClearanceGuard` with the proofs of
:mod:`.finish_guard`: the shank over the pair's own faces by height cells, third faces
by box trees, so that OCCT's segment distances (28-49 ms each on a B-spline face) run
only where the tool really is near a face. Same margins where it matters: a proof only
ever says "clear" when the exact check would (tests/test_finish_guard.py).
"""

from __future__ import annotations

from .finish_guard import FinishGuard


def operation_guard(part, pair: tuple[int, ...], job, reach: float | None = None,
                    shank: float | None = None) -> FinishGuard:
    """The guard of a :class:`~cadcnc.job.Job` (its tool's R', shank length or ``shank``
    mm, the tolerances ``hit`` and ``gouge``) for faces ``pair`` of ``part``."""
    return FinishGuard(part, pair, job.tool.offset,
                       job.tool.shank if shank is None else shank, job.tolerances.hit,
                       reach, job.tolerances.gouge)
