"""Pencil in the fewest setups, one program each (``cadcnc pencil --setups``).

The library chooses the setups (:func:`cadcnc.ops.pencil.fewest_setups.pencil_setups`); each
chosen setup's program is cut back, gated and judged as ``pencil``'s; every output name
gets the setup's axis before its suffix (``P.json`` -> ``P+Z.json``, ``P-X.json``), and
all the setups' outputs are written as one set, all or nothing. The exit code is the
worst of the setups' (a listed axis that reaches nothing: 3).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from ..core.errors import EXIT_NOTHING, EXIT_OK, NothingToCutError
from ..core.job import PRINCIPAL_AXES, Job
from ..geometry.part import load_step
from ..io.output_set import OutputSet, check_destination
from ..io.outputs import SUFFIXES, render
from ..ops.pencil.fewest_setups import AUTO, SetupsResult, axis_tag, parse_setups, pencil_setups
from ..parallel.pool import kept_pools
from ..program.program import Program
from .exit_policy import Verdict, worst
from .operate import Settings, settled_and_judged


@dataclass
class SetupProgram:
    """One chosen setup's settled program (None when cutting back left no cut), its setup
    and its verdict (None then too)."""

    setup: object
    program: Program | None
    verdict: Verdict | None


@dataclass
class SetupsRun:
    """What :func:`run_setups` left: the library's choice (``result``), each chosen
    setup's :class:`SetupProgram`, ``messages`` for the user (stderr, in order), the files
    ``written`` (empty: nothing written), the exit ``code`` and the seconds computing and
    gating."""

    result: SetupsResult
    programs: list[SetupProgram] = field(default_factory=list)
    messages: list[str] = field(default_factory=list)
    written: list[str] = field(default_factory=list)
    code: int = EXIT_OK
    seconds_computed: float = 0.0
    seconds_gated: float = 0.0


def suffixed(out: str, tag: str) -> str:
    """``out`` with the setup's axis before its suffix: P.json -> P+Z.json."""
    p = Path(out)
    return str(p.with_name(f"{p.stem}{tag}{p.suffix}"))


def run_setups(step, job: Job, setups, overlap: float, outputs, settings: Settings, *,
               progress=None, gate_progress=None) -> SetupsRun:
    """Pencil ``job`` on the STEP file ``step`` in the setups ``setups`` ("auto" or axes,
    as :func:`~cadcnc.ops.pencil.fewest_setups.parse_setups`), ``overlap`` mm lapped; write
    ``outputs`` suffixed by each setup's axis (module doc). ``progress``: pencil_setups'
    ``(done, total, what)``; ``gate_progress(what)``: a gate's progress callback."""
    asked = parse_setups(setups)
    for out in outputs:   # every name a setup may take, checked before computing
        for tag in PRINCIPAL_AXES if asked == AUTO else ["+Z"]:
            check_destination(suffixed(out, tag), SUFFIXES, [step])
    t0 = time.monotonic()
    part = load_step(step, flip_material=job.flip_material)
    for n in job.operation.faces or ():
        part.face(n)
    with kept_pools():   # each setup's part has its own workers
        result = pencil_setups(part, job, setups, overlap, progress=progress,
                               max_cycles=settings.max_cycles, processes=settings.processes)
    run = SetupsRun(result, seconds_computed=time.monotonic() - t0)
    codes = [] if asked == AUTO else _unreached(result, run.messages)
    contents = _judged(run, step, job, outputs, settings, codes, gate_progress)
    run.code = worst(codes)
    if contents and all(p.verdict is not None and p.verdict.write for p in run.programs) \
            and (run.code == 0 or settings.allow_partial or settings.allow_gouge):
        OutputSet(list(contents), SUFFIXES, inputs=[step]).write(contents)
        run.written = list(contents)
    run.seconds_gated = time.monotonic() - t0 - run.seconds_computed
    return run


def _unreached(result: SetupsResult, messages: list[str]) -> list[int]:
    """An exit code 3 and a message for each listed axis that reaches no corner."""
    codes = []
    for cand in result.candidates:
        if cand.reached == 0:
            messages.append(f"cadcnc: pencil: setup {cand.setup.name} reaches no corner "
                            f"position{': ' + cand.error if cand.error else ''}")
            codes.append(EXIT_NOTHING)
    return codes


def _judged(run: SetupsRun, step, job: Job, outputs, settings: Settings, codes: list[int],
            gate_progress) -> dict:
    """Each chosen setup's program settled and judged into ``run`` and ``codes``; the
    contents of the outputs of those the verdict writes."""
    contents = {}
    for chosen in run.result.runs:
        what = f"pencil (tool axis {chosen.setup.name})"
        try:
            with kept_pools():
                program, verdict = settled_and_judged(
                    chosen.program, chosen.part, chosen.program.job, step, what, settings,
                    gate_progress=gate_progress(what) if gate_progress else None)
        except NothingToCutError as e:
            run.messages.append(f"cadcnc: {e}")
            codes.append(EXIT_NOTHING)
            run.programs.append(SetupProgram(chosen.setup, None, None))
            continue
        run.messages += verdict.messages
        codes.append(verdict.code)
        run.programs.append(SetupProgram(chosen.setup, program, verdict))
        if verdict.write:
            title = f"{what} R {job.tool.radius:g} of {Path(step).name}"
            contents.update({suffixed(out, axis_tag(chosen.setup)): render(
                program, out, chosen.part, title, **(settings.gcode or {})) for out in outputs})
    return contents
