"""Independent ground truth: check a toolpath against OpenCASCADE.

:func:`verify` measures a :class:`~cadcnc.program.toolpath.Toolpath` with OCCT's own
algorithms, never with the interpolator's arithmetic: the path's contact parameters
(u, w) are used only to seed projections, and a sample is re-projected without seeds to
prove the seeds did not steer the answer. :func:`gouge_gate` runs only the gouge checks
(the pair's faces, the ball against every face of the part at every centre, and the ball
swept along every straight move) and fails closed; the CLI calls it before writing a path.
Sign convention: a surface's deviation is the signed distance of the cutter centre from
it (+ out of the material) minus its offset R' = R + C, so a negative deviation is an
over-cut (a gouge) and a positive one an under-cut (material left). The depth of the ball
into the part is material-aware: OCCT's solid classifier, not a face's side, says which
centres are in the material. Every threshold comes from
:class:`~cadcnc.core.tolerances.Tolerances`. Lengths in mm, times in s. See docs/notes/validation.md
and docs/notes/gate.md.

Modules: :mod:`.records` (one typed record per check), :mod:`.report` (the report and
its JSON), :mod:`.verdict` (its criteria), :mod:`.surface_checks` (per-face deviations),
:mod:`.whole_part` (the ball against every face, at the centres and along the moves),
:mod:`.sweep` (distances along a polyline), :mod:`.bounds` (the segment bound),
:mod:`.material` (faces, boxes and the solid classifier), :mod:`.path_checks` (feed,
theory, stop), :mod:`.reference` (OCCT's intersection curve), :mod:`.gate`, :mod:`.program_gate`
(every cut and link of a program), :mod:`.run`
(:func:`verify`), :mod:`.probe` (OCCT primitives), :mod:`.table` (text).
"""

from __future__ import annotations

from .all_checks import verify
from .check_records import (
    Criterion,
    FeedCheck,
    ReferenceCheck,
    StopCheck,
    SurfaceCheck,
    SweepCheck,
    SweepHit,
    TheoryRow,
    WholePartCheck,
    WholePartHit,
)
from .gate import GateResult, gouge_gate
from .program_gate import ProgramGate, gate_program
from .report import VerificationReport

__all__ = [
    "verify", "gouge_gate", "GateResult", "gate_program", "ProgramGate", "VerificationReport", "SurfaceCheck",
    "ReferenceCheck", "FeedCheck", "TheoryRow", "StopCheck", "WholePartCheck",
    "WholePartHit", "SweepCheck", "SweepHit", "Criterion",
]
