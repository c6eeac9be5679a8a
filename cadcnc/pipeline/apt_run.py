"""An APT-like part program run (``cadcnc run``): each PATH a program of one cut, judged by
the exit policy; written (.json/.csv/.png/.glb one file per path, .ngc one program of
every cut linked at the highest safe height) or streamed as per-period increments.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from .. import apt
from ..core.errors import EXIT_OK, EXIT_PARTIAL
from ..io.output_set import OutputSet, check_destination
from ..io.outputs import SUFFIXES, render
from ..ops.common import single_cut_program
from ..ops.run import check_clearance
from ..program.linking import linked
from ..program.program import Program
from .exit_policy import judge


@dataclass
class AptRun:
    """What :func:`run_apt` left: each path computed as ``(entry, program)``, ``messages``
    for the user (stderr), the files ``written`` and the exit ``code``."""

    paths: list = field(default_factory=list)
    messages: list[str] = field(default_factory=list)
    written: list[str] = field(default_factory=list)
    code: int = EXIT_OK


def run_apt(source: str, outputs, tolerances, clearance, *, gcode: dict | None = None,
            allow_partial: bool = False, allow_gouge: bool = False, progress_of=None,
            gate_progress_of=None) -> AptRun:
    """Run every PATH of the APT-like program ``source`` and write ``outputs`` (module
    doc); with no output, the summaries only (nothing gated). ``gcode``: the G-code
    writer's keywords; ``progress_of(label)`` / ``gate_progress_of(label)``: a path's
    progress callbacks (or None)."""
    for out in outputs:   # every destination checked before any work
        check_destination(out, SUFFIXES, inputs=[source])
    entries, title = apt.read_program(source, tolerances, clearance)
    names = _output_names(outputs, entries)
    written = OutputSet([n for group in names.values() for n in group], SUFFIXES,
                        inputs=[source, *{e.job.source for e in entries}])
    run, programs = AptRun(), []
    for entry, part in apt.check(entries, source):
        check_clearance(part, entry.job)
        label = f"PATH {entry.name}"
        tp = apt.run_job(entry, part, progress_of(label) if progress_of else None, source)
        program = single_cut_program(part, entry.job, tp)
        programs.append((program, part))
        run.paths.append((entry, program))
        if not outputs:   # a summary only: nothing is written, nothing to gate
            run.code = run.code or (EXIT_OK if program.complete else EXIT_PARTIAL)
            continue
        verdict = judge(program, part, f"cadcnc: {source}:{entry.line}: {label}", gcode=gcode,
                        allow_partial=allow_partial, allow_gouge=allow_gouge,
                        progress=gate_progress_of(f"{label}: gouge check")
                        if gate_progress_of else None)
        run.messages += verdict.messages
        if not verdict.write:
            run.code = verdict.code
            return run
        run.code = run.code or verdict.code
    if outputs:
        written.write(_contents(names, programs, title or Path(source).name, gcode))
        run.written = [n for group in names.values() for n in group]
    return run


def _contents(names: dict, programs: list, title: str, gcode: dict | None) -> dict:
    """{file: bytes or str}: .ngc one program of every path, the others one per path."""
    contents = {}
    for out, group in names.items():
        if Path(out).suffix.lower() == ".ngc":
            contents[out] = render(_whole(programs), out, None, title, **gcode)
        else:
            contents.update({name: render(p, name, part, title)
                             for name, (p, part) in zip(group, programs)})
    return contents


def _whole(programs) -> Program:
    """One program of every path's cut, in order, linked at the highest safe height."""
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


def stream_apt(source: str, tolerances, clearance, write, say, *,
               allow_partial: bool = False, allow_gouge: bool = False) -> int:
    """Write each period's increment ``dx dy dz`` (mm) with ``write``. Each path is
    computed and gated first (partial, gouge; ``say`` the verdict's messages), then
    streamed from a fresh stepper: nothing unchecked reaches the axes. The exit code."""
    entries, _ = apt.read_program(source, tolerances, clearance)
    status = EXIT_OK
    for entry, part in apt.check(entries, source):
        tp = apt.run_job(entry, part, None, source)
        verdict = judge(single_cut_program(part, entry.job, tp), part,
                        f"cadcnc: {source}:{entry.line}: PATH {entry.name}",
                        allow_partial=allow_partial, allow_gouge=allow_gouge)
        for line in verdict.messages:
            say(line)
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
    return status

