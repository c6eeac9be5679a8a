"""The subcommands: build the job from the options, call the library, print, write.

Each function takes the argparse namespace and returns the exit code; library errors
propagate to :func:`cadcnc.cli.app.main`, which prints them on one line.
"""

from __future__ import annotations

import sys
from pathlib import Path

from cadcnc.core.errors import InputError
from cadcnc.core.errors import EXIT_PARTIAL
from cadcnc.io.output_set import OutputSet, check_destination
from cadcnc.io.outputs import SUFFIXES, render
from cadcnc.ops.common import single_cut_program
from cadcnc.ops.run import check_clearance
from cadcnc.verification.judgement import judge

from . import demo as demo_command, program_commands
from .feedback import progress, say_error, stage_progress
from .options import clearance, gcode_keywords, tolerances, wants_gcode


# -- run -------------------------------------------------------------------------------------
def run(args) -> int:
    """Execute an APT-like program: each PATH as a program of one cut, judged by the
    library's gate; .json/.csv/.png/.glb one file per path, .ngc one program of every
    cut, linked at the highest safe height."""
    requested = args.output or []
    if args.stream and requested:
        raise InputError("--stream prints increments instead of writing files: give "
                         "either --stream or -o")
    for out in requested:
        check_destination(out, SUFFIXES, inputs=[args.program])
    source = args.program
    from cadcnc import apt  # noqa: PLC0415 - the APT language: only `cadcnc run` pays it

    entries, title = apt.read_program(source, tolerances(args), clearance(args))
    names = _output_names(requested, entries)
    outputs = OutputSet([n for group in names.values() for n in group], SUFFIXES,
                        inputs=[source, *{e.job.source for e in entries}])
    checked = apt.check(entries, source)
    if args.stream:
        return _stream(args, checked, source)
    gcode = gcode_keywords(args) if wants_gcode(requested) else None
    programs, status = [], 0
    for entry, part in checked:
        check_clearance(part, entry.job)
        tp = apt.run_job(entry, part, progress(args, f"PATH {entry.name}"), source)
        program = single_cut_program(part, entry.job, tp)
        programs.append((program, part))
        if not args.quiet:
            print(f"PATH {entry.name} (line {entry.line}): "
                  + program.summary(Path(entry.job.source or "").name))
        if not requested:   # a summary only: nothing is written, nothing to gate
            status = status or (0 if program.complete else EXIT_PARTIAL)
            continue
        verdict = judge(program, part, f"cadcnc: {source}:{entry.line}: PATH {entry.name}",
                        gcode=gcode, allow_partial=args.allow_partial,
                        allow_gouge=args.allow_gouge, progress=stage_progress(
                            args, f"PATH {entry.name}: gouge check", after_s=1.0))
        for line in verdict.messages:
            say_error(line)
        if not verdict.write:
            return verdict.code
        status = status or verdict.code
    contents = {}
    for out, group in names.items():
        if Path(out).suffix.lower() == ".ngc":
            contents[out] = render(_whole(programs), out, None, title or Path(source).name,
                                   **gcode)
        else:
            contents.update({name: render(p, name, part, title or Path(source).name)
                             for name, (p, part) in zip(group, programs)})
    outputs.write(contents)
    if requested and not args.quiet:
        print(f"wrote {', '.join(n for group in names.values() for n in group)}")
    return status


def _whole(programs):
    """One program of every path's cut, in order, linked at the highest safe height."""
    from cadcnc.program.linking import linked
    from cadcnc.program.program import Program

    z = max(max(s.points[:, 2].max() for s in p.links) for p, _ in programs)
    cuts = [c for p, _ in programs for c in p.cuts]
    return Program(programs[0][0].job, linked(cuts, z))


def _output_names(requested, entries) -> dict[str, list[str]]:
    """{OUT: files}: .ngc holds every path; the others one file per path (OUT-NAME.json
    when the program has several)."""
    names = {}
    for out in requested:
        o = Path(out)
        if o.suffix.lower() == ".ngc" or len(entries) == 1:
            names[out] = [out]
        else:
            names[out] = [str(o.with_name(f"{o.stem}-{e.name}{o.suffix}")) for e in entries]
    return names


def _stream(args, checked, source: str) -> int:
    """Print each period's increment. Each path is computed and gated first (partial,
    gouge), then streamed from a fresh stepper: nothing unchecked reaches the axes."""
    from cadcnc import apt  # noqa: PLC0415 - as in run

    write, status = sys.stdout.write, 0
    for entry, part in checked:
        tp = apt.run_job(entry, part, None, source)
        verdict = judge(single_cut_program(part, entry.job, tp), part,
                        f"cadcnc: {source}:{entry.line}: PATH {entry.name}",
                        allow_partial=args.allow_partial, allow_gouge=args.allow_gouge)
        for line in verdict.messages:
            say_error(line)
        if not verdict.write:
            return verdict.code
        status = status or verdict.code
        stepper, increments = apt.stream_job(entry, part, source)
        i, j = entry.job.operation.faces
        write(f"# PATH {entry.name}: faces {i} {j}, period {entry.job.period:g} s, start "
              f"{' '.join(f'{v:.9f}' for v in stepper.p)}\n")
        for dx, dy, dz in increments:
            write(f"{dx:.9f} {dy:.9f} {dz:.9f}\n")
        write(f"# stop after {stepper.cycles} cycles: {stepper.stop_reason}: "
              f"{stepper.stop_detail}\n")
    sys.stdout.flush()
    return status


COMMANDS = {"path": program_commands.path, "run": run,
            "demo": demo_command.demo, "plot": program_commands.plot,
            "verify": program_commands.verify}
