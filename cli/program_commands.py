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
from cadcnc.errors import InputError
from cadcnc.io.output_set import OutputSet
from cadcnc.io.plot import PICTURE_SUFFIXES
from cadcnc.io.program_gcode import program_written_moves
from cadcnc.io.program_json import read_program
from cadcnc.io.program_outputs import PROGRAM_SUFFIXES, render_program
from cadcnc.io.program_plot import program_picture_bytes
from cadcnc.io.program_summary import program_summary
from cadcnc.ops.path.pair_program import program_for_job
from cadcnc.verification import gate_program, verify as run_verify
from cadcnc.verification.program_gate import cut_label

from .feedback import progress, say_error, stage_progress
from .options import job_from_args, program_gcode_options, tolerances, wants_gcode

GOUGE_REFUSED = 5  # exit code: the whole-part check found a gouge deeper than the limit
PARTIAL = 6  # exit code: the program stopped before its intended end


# -- path ------------------------------------------------------------------------------------
def path(args) -> int:
    outputs = OutputSet(args.output, PROGRAM_SUFFIXES, inputs=[args.step])
    job = job_from_args(args, args.step)
    part = cadcnc.load_step(args.step, flip_material=job.flip_material)
    for n in job.operation.faces:  # face numbers checked before anything is computed
        part.face(n)
    gopts = program_gcode_options(args) if wants_gcode(args.output) else None
    i, j = job.operation.faces
    program = program_for_job(part, job, progress=progress(args, f"faces {i} {j}"))
    write, code = judge_program(args, program, part, "path", gopts)
    if not write:
        return code
    title = f"faces {i} {j} of {Path(args.step).name}"
    outputs.write({out: render_program(program, out, part, title, **(gopts or {}))
                   for out in args.output})
    if not args.quiet:
        print(program_summary(program, args.step))
        print(f"  wrote      {', '.join(args.output)}")
    return code


def judge_program(args, program, part, what: str, gopts: dict | None) -> tuple[bool, int]:
    """(write it?, exit code): 0 only for a complete program whose every cut and move
    passed the gouge gate. With G-code options ``gopts`` the gate checks the moves as
    written (points dropped, rounded, tool-tip offset taken back, links); else the
    program's own points (cuts and links). Partial: exit 6, written only with
    ``--allow-partial``; gouge: exit 5, written only with ``--allow-gouge``."""
    write, code = True, 0
    if not program.complete:
        write, code = args.allow_partial, PARTIAL
        why = "; ".join(program.partial_reasons or [
            s.detail for s in program.skipped if s.reason == "stopped short"])
        say_error(f"cadcnc: {what}: partial: {why}"
                  + ("" if write else "; nothing written (--allow-partial writes it)"))
    if not write:
        return write, code
    moves = None if gopts is None else program_written_moves(program, **gopts)
    gate = gate_program(program, part, program.job.tolerances, moves=moves,
                        blend_mm=0.0 if gopts is None else gopts["blend"],
                        progress=stage_progress(args, f"{what}: gouge check", after_s=1.0))
    if gate.ok:
        return write, code
    write, code = args.allow_gouge, GOUGE_REFUSED
    if write:
        say_error(f"cadcnc: {what}: {gate.message.replace('refused: ', '')}; written "
                  "anyway (--allow-gouge)")
    else:
        say_error(f"cadcnc: {what}: refused: {gate.message.replace('refused: ', '')}; "
                  f"nothing written. {_hint(program, gate, gopts)}--allow-gouge writes it")
    return write, code


def _hint(program, gate, gopts) -> str:
    """What may help: fewer dropped points when only moves between written points cut;
    a smaller ball for a shallow side cut of a cut (not for a link, nor in the material)."""
    if any(gate.link_failed):
        return "A higher --clearance (links above the part) may pass; "
    bad = [(seg, r) for seg, r in zip(program.cuts, gate.results) if not r.ok]
    if gopts and gopts.get("tolerance") and not any(
            h.depth_mm > r.limit_mm for _, r in bad for h in r.hits):
        return "A smaller --tolerance (fewer points dropped) may pass; "
    shallow = all(math.isfinite(r.depth_mm) and r.depth_mm < program.job.tool.offset
                  and not r.in_material and r.hits for _, r in bad)
    return "A smaller --radius may fit; " if bad and shallow else ""


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
        job = job_from_args(args, args.input)
        part = cadcnc.load_step(args.input, flip_material=job.flip_material)
        program = program_for_job(part, job, progress=progress(args, "verify"))
    if not program.cuts:
        raise InputError(f"{args.input}: the program has no cut to verify")
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
    code = 0
    for lab, r in zip(labels, reports):
        if r.ok(tol.gouge):
            continue
        code = GOUGE_REFUSED
        where = f"{lab}: " if len(reports) > 1 else ""
        if not math.isfinite(r.max_gouge_mm):
            say_error(f"cadcnc: verify: {where}the gouge depth could not be measured")
            continue
        failed = [c for c in r.criteria(tol.gouge) if not c.ok]
        say_error(f"cadcnc: verify: {where}failed " + "; ".join(
            f"{c.name} {c.value:.4g} (limit {c.limit:g})" for c in failed))
    return code
