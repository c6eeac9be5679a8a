"""Programs already computed: read one with its part, picture it, verify it against OCCT
(``cadcnc plot`` and ``cadcnc verify``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from ..core.errors import EXIT_GOUGE, EXIT_OK, InputError
from ..core.job import Job
from ..core.tolerances import Tolerances
from ..core.work_limits import MAX_VERIFY_POINTS, refuse_over
from ..geometry.part import load_step
from ..io.output_set import OutputSet
from ..io.plot import PICTURE_SUFFIXES
from ..io.program_json import read_program
from ..io.program_plot import program_picture_bytes
from ..ops.path.pair_program import program_for_job
from ..verification import VerificationReport, gate_program, verify
from ..verification.program_gate import cut_label


def load_saved(path_json, part_file: str | None):
    """(program, part) of a saved program or path JSON; the part from ``part_file`` or
    the file the job records (looked up beside the JSON when relative)."""
    program = read_program(path_json)
    if part_file is None:
        part_file = program.job.source
        if not part_file:
            raise InputError(f"{path_json}: records no part file; give --part PART.step")
        if not Path(part_file).is_absolute() and not Path(part_file).exists():
            near = Path(path_json).parent / part_file
            part_file = str(near) if near.exists() else part_file
    part = load_step(part_file, flip_material=program.job.flip_material)
    for cut in program.cuts:
        for n in cut.path.faces:
            if n is not None:
                part.face(n)
    return program, part


def plot_saved(path_json, part_file: str | None, output) -> None:
    """Write the picture (.png or .glb) of the program saved in ``path_json``."""
    outputs = OutputSet([output], PICTURE_SUFFIXES, inputs=[path_json, part_file])
    program, part = load_saved(path_json, part_file)
    outputs.write({output: program_picture_bytes(program, part, output,
                                                 Path(path_json).name)})


@dataclass
class VerifyRun:
    """What :func:`verify_program` left: one report and label per cut, ``messages`` for
    the user (stderr) and the exit code (5 when a cut or a link gouges)."""

    reports: list[VerificationReport]
    labels: list[str]
    messages: list[str] = field(default_factory=list)
    code: int = EXIT_OK


def verify_program(source: str, tol: Tolerances, *, part_file: str | None = None,
                   job: Job | None = None, progress=None, cut_progress=None,
                   links_progress=None) -> VerifyRun:
    """Verify every cut of a program against OCCT: the program saved in ``source`` (a
    .json) or computed from ``job`` on the STEP file ``source``; then its links by the
    operations' gate. ``progress``: the computation's ``Progress`` (cycles, 0, the distance);
    ``cut_progress()`` / ``links_progress()``: a new ``(stage, done, total)`` callback for
    each cut's checks and for the links gate, made when they start."""
    if job is None:
        program, part = load_saved(source, part_file)
    else:
        part = load_step(source, flip_material=job.flip_material)
        program = program_for_job(part, job, progress=progress)
    if not program.cuts:
        raise InputError(f"{source}: the program has no cut to verify")
    refuse_over(f"verifying {source}", sum(len(s.points) for s in program.segments),
                MAX_VERIFY_POINTS, "points", "verify a shorter program, or one cut at a time")
    run = VerifyRun([verify(seg.path, part, tol=tol,
                            progress=cut_progress() if cut_progress else None)
                     for seg in program.cuts],
                    [cut_label(k, seg) for k, seg in enumerate(program.cuts, 1)])
    _judge_links(run, program, part, tol, links_progress)
    _judge_cuts(run, tol)
    return run


def _judge_links(run: VerifyRun, program, part, tol: Tolerances, progress) -> None:
    """The whole program's links by the operations' gate (a report covers the cuts
    only); a program of cuts alone has no link to judge."""
    if not program.links:
        return
    gate = gate_program(program, part, tol, progress=progress() if progress else None)
    if any(gate.link_failed):
        run.code = EXIT_GOUGE
        run.messages.append(f"cadcnc: verify: links fail the gouge gate: {gate.message}")


def _judge_cuts(run: VerifyRun, tol: Tolerances) -> None:
    """Exit 5 and a message for each cut whose report fails."""
    several = len(run.reports) > 1
    for lab, r in zip(run.labels, run.reports):
        if r.ok(tol.gouge):
            continue
        run.code = EXIT_GOUGE
        where = f"{lab}: " if several else ""
        if not math.isfinite(r.max_gouge_mm):
            run.messages.append(f"cadcnc: verify: {where}the gouge depth could not be "
                                "measured")
            continue
        failed = [c for c in r.criteria(tol.gouge) if not c.ok]
        run.messages.append(f"cadcnc: verify: {where}failed " + "; ".join(
            f"{c.name} {c.value:.4g} (limit {c.limit:g})" for c in failed))
