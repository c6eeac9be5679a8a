"""Cut a program's gouging cuts back to their last verified point (operations' programs).

An operation that builds a program (pencil) does not throw the whole program away when one
cut gouges: :func:`cut_back` gates each cut on its own points and moves
(:func:`~cadcnc.verification.gate.gouge_gate`), keeps every cut that passes, cuts a
failing one back to the last point before its first failing centre or move, lists the rest
under ``skipped`` (reason ``gouge``, with the gate's message), and links the cuts again,
each entered by the operations' rule (:mod:`cadcnc.ops.entries`).
The program it returns is then gated whole, written moves and links included, as any
program. Lengths mm.
"""

from __future__ import annotations

from ..ops.entries import entered_program_segments
from ..program.program import CutSegment, Program, Skipped
from ..program.toolpath import toolpath_head
from .gate import gouge_gate
from .gate_jobs import gate_cuts

GOUGE = "gouge"
CUT_BACK = "cut back"  # the stop reason of a cut cut back to its last verified point


def _first_failure(gate, limit: float) -> int | None:
    """Index of the first point not to keep (None: nothing located)."""
    firsts = [h.cycles[0][0] for h in gate.hits if h.depth_mm > limit and h.cycles]
    if gate.sweep is not None:
        firsts += [h.moves[0][0] + 1 for h in gate.sweep.hits
                   if h.depth_mm > gate.sweep.allowance_mm and h.moves]
    return min(firsts) if firsts else None


def cut_back(program: Program, part, z_safe: float, join: float = 0.0, *,
             jobs: int | None = 1, reference: bool = False, progress=None) -> Program:
    """``program`` with every gouging cut cut back (see the module doc). ``jobs``,
    ``reference``, ``progress``: as for :func:`~.program_gate.gate_program`."""
    tol = program.job.tolerances
    cuts, skipped = [], list(program.skipped)
    changed = False
    gates = gate_cuts(part, [(seg.path, None, 0.0, None) for seg in program.cuts], tol,
                      jobs=jobs, reference=reference, progress=progress)
    for seg, gate in zip(program.cuts, gates):
        if gate.ok:
            cuts.append(seg)
            continue
        changed = True
        n = _first_failure(gate, tol.gouge)
        keep = None
        if n is not None and n >= 2:
            head = toolpath_head(seg.path, n, CUT_BACK, gate.message)
            if gouge_gate(head, part, tol, reference=reference).ok:
                keep = CutSegment(head, seg.edge, seg.stretch, at_limit=True)
        if keep is not None:
            cuts.append(keep)
        kept = 0 if keep is None else len(keep.points)
        skipped.append(Skipped(seg.path.faces, GOUGE, (
            f"{'cut back after ' + str(kept) + ' of ' if kept else 'all '}"
            f"{len(seg.points)} points: {gate.message}"), seg.edge))
    if not changed:
        return program
    segments, unreachable, _ = entered_program_segments(part, program.job, cuts, z_safe,
                                                        join=join, processes=jobs)
    return Program(program.job, segments, skipped + unreachable, program.notes)
