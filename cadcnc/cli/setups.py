"""``cadcnc pencil PART --setups auto|+Z,-X,...``: the fewest setups, one program each.

The library chooses the setups (:func:`cadcnc.ops.pencil.fewest_setups.pencil_setups`); each
chosen setup's program is cut back, gated and judged as ``pencil``'s; every output name
gets the setup's axis before its suffix (``P.json`` -> ``P+Z.json``, ``P-X.json``), and
all the setups' outputs are written as one set, all or nothing. The exit code is the
worst of the setups' (a listed axis that reaches nothing: 3).
"""

from __future__ import annotations

import time
from pathlib import Path

from .feedback import say_error, stage_progress


def suffixed(out: str, tag: str) -> str:
    """``out`` with the setup's axis before its suffix: P.json -> P+Z.json."""
    p = Path(out)
    return str(p.with_name(f"{p.stem}{tag}{p.suffix}"))


def setups_command(args) -> int:
    import cadcnc
    from cadcnc.core.errors import EXIT_NOTHING, InputError, NothingToCutError
    from cadcnc.io.output_set import OutputSet, check_destination
    from cadcnc.io.outputs import SUFFIXES, render
    from cadcnc.core.job import PRINCIPAL_AXES
    from cadcnc.ops.common import safe_height
    from cadcnc.ops.pencil.pencil_program import CHAIN_GAP
    from cadcnc.ops.pencil.fewest_setups import AUTO, axis_tag, parse_setups, pencil_setups
    from cadcnc.core.units import parse_length
    from cadcnc.parallel.pool import check_jobs, kept_pools
    from cadcnc.verification.judgement import judge, settle, worst

    from .options import gcode_keywords, pencil_job, wants_gcode

    if getattr(args, "axis", None) is not None:
        raise InputError("give --axis or --setups, not both")
    if getattr(args, "stream", None):
        raise InputError("--stream takes one program: stream a setup's with --axis")
    asked = parse_setups(args.setups)
    for out in args.output:   # every name a setup may take, checked before computing
        for tag in PRINCIPAL_AXES if asked == AUTO else ["+Z"]:
            check_destination(suffixed(out, tag), SUFFIXES, [args.step])
    overlap = parse_length(args.setup_overlap, "--setup-overlap")
    job = pencil_job(args, args.step)
    t0 = time.monotonic()
    part = cadcnc.load_step(args.step, flip_material=job.flip_material)
    for n in job.operation.faces or ():
        part.face(n)
    report = None if args.quiet else (lambda done, total, what: None)
    jobs = check_jobs(getattr(args, "jobs", None))
    with kept_pools():   # each setup's part has its own workers
        result = pencil_setups(part, job, args.setups, overlap, progress=report,
                               max_cycles=args.max_cycles, jobs=jobs)
    t_cut = time.monotonic() - t0
    name = Path(args.step).name
    gcode = gcode_keywords(args) if wants_gcode(args.output) else None
    codes, contents, writes = [], {}, []
    if asked != AUTO:
        for run in result.candidates:
            if run.reached == 0:
                say_error(f"cadcnc: pencil: setup {run.setup.name} reaches no corner position"
                          f"{': ' + run.error if run.error else ''}")
                codes.append(EXIT_NOTHING)
    for run in result.runs:
        tag = axis_tag(run.setup)
        what = f"pencil (tool axis {run.setup.name})"
        try:
            program = settle(run.program, run.part, safe_height(run.part, run.program.job),
                             CHAIN_GAP, f"{args.step}: {what}", args.allow_gouge)
        except NothingToCutError as e:
            say_error(f"cadcnc: {e}")
            codes.append(EXIT_NOTHING)
            writes.append(False)
            continue
        with kept_pools():
            verdict = judge(program, run.part, f"cadcnc: {what}", gcode=gcode,
                            allow_partial=args.allow_partial, allow_gouge=args.allow_gouge,
                            progress=stage_progress(args, f"{what}: gouge check", after_s=1.0),
                            jobs=jobs)
        for line in verdict.messages:
            say_error(line)
        codes.append(verdict.code)
        writes.append(verdict.write)
        if not args.quiet:
            print(program.summary(f"{name} setup {run.setup.name}"))
            print("  setup      " + "; ".join(run.setup.describe()))
        if verdict.write:
            title = f"{what} R {job.tool.radius:g} of {name}"
            contents.update({suffixed(out, tag): render(program, out, run.part, title,
                                                        **(gcode or {}))
                             for out in args.output})
    code = worst(codes)
    write = bool(contents) and all(writes) and (code == 0 or args.allow_partial
                                                or args.allow_gouge)
    if write:
        OutputSet(list(contents), SUFFIXES, inputs=[args.step]).write(contents)
    if not args.quiet:
        for line in result.summary_lines():
            print(line)
        print("verdict    " + ("written: " + ", ".join(contents) if write else
                               "nothing written") + ("" if code == 0 else f" (exit {code})"))
        print(f"time       computed in {t_cut:.1f} s, gated in "
              f"{time.monotonic() - t0 - t_cut:.1f} s")
    return code
