"""The third-face and shank guard of every operation's stepper and stretch search.

:class:`~cadcnc.geometry.clearance.ClearanceGuard` with the proofs of
:mod:`.finish_guard`: the shank over the pair's own faces by height cells, third faces
by box trees, so that OCCT's segment distances (28-49 ms each on a B-spline face) run
only where the tool really is near a face. Same margins where it matters: a proof only
ever says "clear" when the exact check would (tests/test_finish_guard.py).
"""

from __future__ import annotations

from .finish_guard import FinishGuard

OWN_SHARE = 0.7
"""Share of the gouge limit by which the ball may come nearer than R' to its own faces'
edges (the guard's own-face rule), so that a stretch ending there passes the gate of the
program as written: of the limit, the G64 P blending takes 0.1 (io.gcode.BLEND_SHARE),
the rounding of the written coordinates up to 0.1 (tolerance / 10) and the chords
between points the rest. With the whole limit a cut ending on a B-spline face's edge
(edge tolerance 8.7 um in bug32596_abc_0_13.step) reached 0.9998-1.005 um and the gate
refused the whole program (exit 5): pencil at R 2 and R 3, `cadcnc path` on faces 5/67."""


def operation_guard(part, pair: tuple[int, ...], job, reach: float | None = None,
                    shank: float | None = None) -> FinishGuard:
    """The guard of a :class:`~cadcnc.job.Job` (its tool's R', shank length or ``shank``
    mm, the tolerance ``hit`` for third faces, OWN_SHARE of ``gouge`` for its own faces'
    edges) for faces ``pair`` of ``part``."""
    return FinishGuard(part, pair, job.tool.offset,
                       job.tool.shank if shank is None else shank, job.tolerances.hit,
                       reach, OWN_SHARE * job.tolerances.gouge)
