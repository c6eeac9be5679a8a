"""``path``, ``verify`` and ``plot``: programs (every stretch of a corner, cut and linked).

``path`` runs :func:`cadcnc.ops.path.pair_program.program_for_job`, gates the whole program
(every cut, every move written, links included) and writes it by suffix; ``verify`` and
``plot`` read a program JSON (version 2) or a toolpath JSON (version 1).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import cadcnc
from cadcnc.core.errors import EXIT_GOUGE, InputError
from cadcnc.io.output_set import OutputSet
from cadcnc.io.plot import PICTURE_SUFFIXES
from cadcnc.io.program_json import read_program
from cadcnc.io.program_plot import program_picture_bytes
from cadcnc.ops.path.pair_program import program_for_job
from cadcnc.verification import gate_program, verify as run_verify
from cadcnc.verification.program_gate import cut_label
from cadcnc.core.work_limits import MAX_VERIFY_POINTS, refuse_over

from .feedback import progress, say_error, stage_progress
from .operation import operation_command
from .options import path_job, tolerances


# -- path ------------------------------------------------------------------------------------
def path(args) -> int:
    i, j = args.faces
    return operation_command(args, "path", path_job, progress=progress(args, f"faces {i} {j}"))


# -- plot and verify of saved programs -------------------------------------------------------
def load_saved(path_json: str, part_file: str | None):
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
    part = cadcnc.load_step(part_file, flip_material=program.job.flip_material)
    for cut in program.cuts:
        for n in cut.path.faces:
            if n is not None:
                part.face(n)
    return program, part


def plot(args) -> int:
    outputs = OutputSet([args.output], PICTURE_SUFFIXES, inputs=[args.path_json, args.part])
    program, part = load_saved(args.path_json, args.part)
    title = Path(args.path_json).name
    outputs.write({args.output: program_picture_bytes(program, part, args.output, title)})
    if not args.quiet:
        print(f"wrote {args.output}")
    return 0


def verify(args) -> int:
    """Verify every cut of a program (computed, or read from JSON) against OCCT; one
    report per cut. Exit 5 when any cut gouges beyond --gouge-tolerance."""
    tol = tolerances(args)
    if args.input.lower().endswith(".json"):
        program, part = load_saved(args.input, args.part)
    else:
        if args.part is not None:
            raise InputError("--part is for a saved PATH.json; a STEP input is the part")
        job = path_job(args, args.input)
        part = cadcnc.load_step(args.input, flip_material=job.flip_material)
        program = program_for_job(part, job, progress=progress(args, "verify"))
    if not program.cuts:
        raise InputError(f"{args.input}: the program has no cut to verify")
    refuse_over(f"verifying {args.input}", sum(len(s.points) for s in program.segments),
                MAX_VERIFY_POINTS, "points", "verify a shorter program, or one cut at a time")
    reports = [run_verify(seg.path, part, tol=tol, progress=stage_progress(args, "verify"))
               for seg in program.cuts]
    labels = [cut_label(k, seg) for k, seg in enumerate(program.cuts, 1)]
    if args.json:
        data = [r.to_dict() for r in reports]
        print(json.dumps(data[0] if len(data) == 1 else {
            "ok": all(r.ok(tol.gouge) for r in reports),
            "cuts": [{"cut": lab, **d} for lab, d in zip(labels, data)]}, indent=1))
    else:
        for lab, r in zip(labels, reports):
            print((f"{lab}\n" if len(reports) > 1 else "") + r.format_table(tol.gouge))
    code = _links_verdict(program, part, tol, args)
    for lab, r in zip(labels, reports):
        if r.ok(tol.gouge):
            continue
        code = EXIT_GOUGE
        where = f"{lab}: " if len(reports) > 1 else ""
        if not math.isfinite(r.max_gouge_mm):
            say_error(f"cadcnc: verify: {where}the gouge depth could not be measured")
            continue
        failed = [c for c in r.criteria(tol.gouge) if not c.ok]
        say_error(f"cadcnc: verify: {where}failed " + "; ".join(
            f"{c.name} {c.value:.4g} (limit {c.limit:g})" for c in failed))
    return code


def _links_verdict(program, part, tol, args) -> int:
    """The whole program's links by the operations' gate (a report covers the cuts
    only): 0 when every link move is clear, else the exit code of a gouge, said on
    stderr. A program of cuts alone has no link to judge."""
    if not program.links:
        return 0
    gate = gate_program(program, part, tol,
                        progress=stage_progress(args, "verify: links", after_s=1.0))
    bad = [lab for lab, failed in zip(gate.labels, gate.link_failed) if failed]
    if not bad:
        return 0
    say_error(f"cadcnc: verify: links fail the gouge gate: {gate.message}")
    return EXIT_GOUGE
