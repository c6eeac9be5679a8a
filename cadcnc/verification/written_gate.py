"""The whole-program gate of a program as it will be written: with G-code options, the moves
of the G-code (points dropped, rounded, tool-tip offset taken back, links); else the
program's own points. A measurement: what it means for the exit code is
:mod:`cadcnc.pipeline.exit_policy`'s."""

from __future__ import annotations

from ..io.program_gcode import program_written_moves
from ..program.program import Program
from .program_gate import ProgramGate, gate_program


def gate_written(program: Program, part, gcode: dict | None = None, *, progress=None,
                 jobs: int | None = 1) -> ProgramGate:
    """The :class:`ProgramGate` of ``program`` on ``part`` at its job's tolerances.
    ``gcode``: keywords of :func:`~cadcnc.io.program_gcode.program_ngc` when a .ngc is
    written (their ``blend`` the G64 P blending, mm), else None; ``progress``: the gate's
    ``(stage, done, total)`` callback; ``jobs``: processes gating the cuts (None: every
    core); the gate does not depend on it."""
    moves = None if gcode is None else program_written_moves(program, **gcode)
    return gate_program(program, part, program.job.tolerances, moves=moves,
                        blend_mm=0.0 if gcode is None else gcode["blend"], progress=progress,
                        jobs=jobs)
