"""The exit-code policy: what a run writes and which exit code it returns, for every
operation. Gouging cuts are cut back (pencil, finish), the whole program is gated as written
(:mod:`cadcnc.verification.written_gate`, the measurement), and partial and gouging
programs are refused unless the user allows them.

Exit codes (docs/reliability.md) are those of :mod:`cadcnc.core.errors`: 0 only for a complete
program whose every cut and every written move passed the gouge gate; 5 a gouge; 6 partial.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..core.errors import (
    EXIT_GOUGE,
    EXIT_INPUT,
    EXIT_INTERNAL,
    EXIT_NOTHING,
    EXIT_OK,
    EXIT_OUTPUT,
    EXIT_PARTIAL,
    NothingToCutError,
)
from ..program.program import FAILED, STOPPED_SHORT, Program
from ..program.summary import skipped_counts
from ..verification.cut_back import cut_back
from ..verification.program_gate import ProgramGate
from ..verification.written_gate import gate_written


@dataclass
class Verdict:
    """``write``: whether the outputs may be written; ``code``: the exit code; ``messages``:
    sentences for the user (stderr); ``gate``: the whole-program gate (None when not run)."""

    write: bool
    code: int
    messages: list[str] = field(default_factory=list)
    gate: ProgramGate | None = None


def settle(program: Program, part, z_safe: float, join: float, what: str,
           allow_gouge: bool = False, *, processes: int | None = 1) -> Program:
    """The program with each gouging cut cut back to its last verified point and the rest
    listed as skipped (unless ``allow_gouge``); NothingToCutError when no cut is left.
    ``processes``: processes gating the cuts (None: every core)."""
    if not allow_gouge:
        program = cut_back(program, part, z_safe, join, jobs=processes)
    if not program.cuts:
        raise NothingToCutError(f"{what}: no cut left: "
                                f"{skipped_counts(program) or 'nothing to cut'}")
    return program


def judge(program: Program, part, what: str, *, gcode: dict | None = None,
          allow_partial: bool = False, allow_gouge: bool = False, progress=None,
          processes: int | None = 1) -> Verdict:
    """The :class:`Verdict` on ``program``. With G-code options ``gcode`` (keywords of
    :func:`~cadcnc.io.program_gcode.program_ngc`) the gate checks the moves as written
    (points dropped, rounded, tool-tip offset taken back, links); else the program's own
    points. A partial program exits 6 and is written only with ``allow_partial``; a
    gouging one exits 5 and is written only with ``allow_gouge``. ``processes``: processes
    gating the cuts (None: every core); the verdict does not depend on it."""
    verdict = Verdict(True, EXIT_OK)
    if not program.complete:
        verdict.write, verdict.code = allow_partial, EXIT_PARTIAL
        why = "; ".join(program.partial_reasons + [
            f"faces {' '.join(map(str, s.faces))}: {s.reason}: {s.detail}"
            for s in program.skipped if s.reason in (STOPPED_SHORT, FAILED)
        ]) or "a cut stopped short of its end"
        verdict.messages.append(f"{what}: partial: {why}" + (
            "" if allow_partial else "; nothing written (--allow-partial writes it)"))
    if not verdict.write:
        return verdict
    gate = gate_written(program, part, gcode, progress=progress, jobs=processes)
    verdict.gate = gate
    if gate.ok:
        return verdict
    verdict.write, verdict.code = allow_gouge, EXIT_GOUGE
    why = gate.message.replace("refused: ", "")
    if allow_gouge:
        verdict.messages.append(f"{what}: {why}; written anyway (--allow-gouge)")
    else:
        verdict.messages.append(f"{what}: refused: {why}; nothing written. "
                                f"{hint(program, gate, gcode)}--allow-gouge writes it")
    return verdict


SEVERITY = (EXIT_OK, EXIT_NOTHING, EXIT_PARTIAL, EXIT_GOUGE, EXIT_OUTPUT, EXIT_INPUT,
            EXIT_INTERNAL)
"""Exit codes from the least to the most severe: a run of several programs (setups)
exits with its worst."""


def worst(codes) -> int:
    """The most severe of ``codes`` (SEVERITY order; EXIT_OK for none)."""
    return max(codes, key=lambda c: SEVERITY.index(c) if c in SEVERITY else len(SEVERITY),
               default=EXIT_OK)


def across_parts(codes) -> int:
    """The exit code of a run over several parts (``cadcnc batch``) from each part's:
    EXIT_OK when every part exited 0 (or there are none); the parts' one code when every
    part that did not exit 0 exited that same code and none exited 0; else EXIT_PARTIAL
    (some parts done, some not: the summary says which). One part's several programs (its
    setups) exit with the :func:`worst` instead: they are one result."""
    codes = set(codes)
    if codes <= {EXIT_OK}:
        return EXIT_OK
    return codes.pop() if len(codes) == 1 else EXIT_PARTIAL


def hint(program: Program, gate: ProgramGate, gcode: dict | None) -> str:
    """What may help, only where it can: fewer dropped points when only moves between
    written points cut; a smaller ball for a shallow side cut (not in the material)."""
    bad = [(seg, r) for seg, r in zip(program.cuts, gate.results) if not r.ok]
    if any(gate.link_failed):
        return ""
    if gcode and gcode.get("tolerance") and not any(
            h.depth_mm > r.limit_mm for _, r in bad for h in r.hits):
        return "A smaller --tolerance (fewer points dropped) may pass; "
    shallow = all(math.isfinite(r.depth_mm) and r.depth_mm < program.job.tool.offset
                  and not r.in_material and r.hits for _, r in bad)
    return "A smaller --radius may fit; " if bad and shallow else ""
