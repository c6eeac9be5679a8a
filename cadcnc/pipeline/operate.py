"""One operation on one STEP part, end to end, as ``cadcnc path``/``pencil``/``finish`` run
it: load, plan (:func:`~cadcnc.pipeline.program_plan.plan`), cut gouging cuts back, gate and judge
(:mod:`cadcnc.pipeline.exit_policy`), render the outputs by suffix
(:mod:`cadcnc.io.outputs`). The command line and every batch task call this one function,
so that a part in a batch gives the bytes it gives alone.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, TypeVar

import numpy as np

from ..core.errors import CadcncError, InputError, NothingToCutError
from ..core.job import Job
from ..core.work_limits import MAX_CYCLES
from ..geometry.part import Part, load_step
from ..geometry.setup import setup_in, setup_part
from ..io.outputs import RenderPieces, render_all, render_piece
from ..ops.common import safe_height
from ..ops.run import cut_back_gap
from ..parallel.pool import check_jobs
from ..parallel.tasks import beside
from ..program.program import Program
from ..verification.gate_cache import open_shared
from .exit_policy import Verdict, judge, settle
from .program_plan import plan

T = TypeVar("T")


@dataclass(frozen=True)
class Settings:
    """How a program is judged and written besides its Job: ``max_cycles`` (the work
    limit), ``gcode`` (keywords of :func:`~cadcnc.io.program_gcode.program_ngc` when a
    .ngc is written, else None: the gate then checks the program's own points),
    ``allow_partial`` / ``allow_gouge`` (write a partial or gouging program anyway),
    ``processes``: processes computing and gating (:mod:`cadcnc.parallel`; a batch task
    runs one; the ``--jobs`` option)."""

    max_cycles: int = MAX_CYCLES
    gcode: dict | None = field(default=None, hash=False)
    allow_partial: bool = False
    allow_gouge: bool = False
    processes: int = 1


@dataclass
class Outcome:
    """What :func:`operate` leaves: the part (turned to its setup), the program, the
    verdict, the seconds spent computing (load and :func:`~cadcnc.pipeline.program_plan.plan`) and settling and
    gating, and ``what``: the operation's name in messages, with its tool axis."""

    part: Part
    program: Program
    verdict: Verdict
    seconds_computed: float
    seconds_gated: float
    what: str
    contents: dict | None = None
    """The outputs asked of :func:`operate`, rendered beside the gate (None: not made)."""


MAX_ORIGIN_OFFSET = 10_000.0
"""mm: the farthest a work zero (``--origin``) may lie from the part's bounding box along
any axis (10 m,
beyond any machine's travel; far enough off, the part's coordinates lose their digits)."""


def check_origin(part: Part, job: Job, step) -> None:
    """InputError when the job's work zero lies more than MAX_ORIGIN_OFFSET from the
    part's bounding box along an axis (an input mistake, not a geometry without a program)."""
    if job.origin is None:
        return
    lo, hi = (np.asarray(b, dtype=float) for b in part.bounding_box())
    origin = np.asarray(job.origin, dtype=float)
    off = float(np.max(np.maximum(0.0, np.maximum(lo - origin, origin - hi))))
    if not off <= MAX_ORIGIN_OFFSET:
        shown = ",".join(f"{v:g}" for v in origin)
        raise InputError(f"--origin {shown}: {off:.3g} mm from {Path(str(step)).name}'s "
                         f"bounding box; the work zero must lie within "
                         f"{MAX_ORIGIN_OFFSET:g} mm of the part")


def operate(step, job: Job, what: str, settings: Settings = Settings(), *, progress=None,
            times: dict | None = None, gate_progress=None, outputs=()) -> Outcome:
    """Run ``job`` on the STEP file ``step`` and judge it (module doc). ``what``: the
    command's name in messages ("pencil"); ``progress`` and ``times``: as
    :func:`~cadcnc.pipeline.program_plan.plan`; ``gate_progress``: the gate's ``(done, total, stage)`` callback.
    ``outputs``: files the caller will write (by suffix): with more than one process
    they are rendered on the workers while this process gates the program
    (``Outcome.contents``; :func:`rendered` gives them). Raises the library's errors
    (bad face number, nothing to cut, ...)."""
    if settings.max_cycles < 1:
        raise InputError(f"--max-cycles must be at least 1, got {settings.max_cycles}")
    t0 = time.monotonic()
    loaded = load_step(step, flip_material=job.flip_material)
    check_origin(loaded, job, step)
    part = setup_part(loaded, job)
    if setup_in(part) is not None:
        what = f"{what} (tool axis {setup_in(part).name})"
    for n in getattr(job.operation, "faces", None) or ():
        if n is not None:
            part.face(n)   # face numbers checked before anything is computed
    try:
        program = plan(part, job, progress=progress, times=times,
                       max_cycles=settings.max_cycles, processes=settings.processes)
    except NothingToCutError as e:   # a setup that reaches nothing says which it is
        if setup_in(part) is None:
            raise
        raise NothingToCutError(f"{what}: {e}") from None
    t_cut = time.monotonic() - t0
    program, verdict, contents = _settled(program, part, job, step, what, settings,
                                          gate_progress, list(outputs))
    return Outcome(part, program, verdict, t_cut, time.monotonic() - t0 - t_cut, what,
                   contents)


def settled_and_judged(program: Program, part: Part, job: Job, step, what: str,
                       settings: Settings, *, gate_progress=None) -> tuple[Program, Verdict]:
    """``program`` with its gouging cuts cut back (pencil, finish: :func:`settle`) and its
    :class:`Verdict` (:func:`judge`), as ``settings`` ask; ``job`` gives the links' safe
    height; ``step`` and ``what`` name the run in messages. NothingToCutError when no cut
    is left. The program gate runs first: when every written move passes, no cut gouges
    and there is nothing to cut back (the cut-back's own gate is spared); otherwise the
    gouging cuts are cut back and the program gated again. Both share their work on
    ``part`` (:func:`~cadcnc.verification.gate_cache.open_shared`: kept on it from now on)."""
    program, verdict, _ = _settled(program, part, job, step, what, settings, gate_progress)
    return program, verdict


def _settled(program: Program, part: Part, job: Job, step, what: str, settings: Settings,
             gate_progress=None, outputs: list | None = None
             ) -> tuple[Program, Verdict, dict | None]:
    """:func:`settled_and_judged`, and the contents of ``outputs`` when they were
    rendered on the workers beside the gate of the program returned (else None)."""
    open_shared(part)
    join = cut_back_gap(job)
    if join is None and not program.cuts:
        raise NothingToCutError(f"{step}: {what}: nothing to cut")
    jobs = check_jobs(settings.processes)

    def judged(program: Program) -> tuple[Verdict, dict | None]:
        def verdict() -> Verdict:
            return judge(program, part, f"cadcnc: {what}", gcode=settings.gcode,
                         allow_partial=settings.allow_partial,
                         allow_gouge=settings.allow_gouge, progress=gate_progress,
                         processes=settings.processes)

        if not outputs or jobs == 1:
            return verdict(), None
        pieces = RenderPieces(program, outputs, part, _title(program, what), jobs,
                              settings.gcode or {})
        # this process makes its outputs first: the workers have the JSON to make before
        # the gate's tasks reach them
        (here, found), done = beside(lambda: (_kept(pieces.here), verdict()), _render_kept,
                                     pieces.tasks, part, jobs, "writing outputs",
                                     pieces.sizes)
        if isinstance(here, CadcncError) or any(isinstance(d, CadcncError) for d in done):
            return found, None   # made again, and refused, only if the verdict writes them
        return found, pieces.joined(here, done)

    if join is not None and program.cuts and not settings.allow_gouge:
        verdict, contents = judged(program)
        if verdict.gate is not None and verdict.gate.ok:
            return program, verdict, contents
    if join is not None:
        program = settle(program, part, safe_height(part, job), join, f"{step}: {what}",
                         settings.allow_gouge, processes=settings.processes)
    return (program, *judged(program))


def _kept(fn: Callable[[], T]) -> T | CadcncError:
    """``fn()``, or the library error it raised: an output made ahead of the verdict
    fails only where the verdict asks for it (the gate's exit code comes first)."""
    try:
        return fn()
    except CadcncError as e:
        return e


def _render_kept(part, task, beat=None):
    """:func:`~cadcnc.io.outputs.render_piece` (an on_workers task), its library error
    returned, not raised (:func:`_kept`)."""
    return _kept(lambda: render_piece(part, task))


def _title(program: Program, what: str) -> str:
    """The outputs' title: the operation, the ball and the part's file name."""
    job = program.job
    return f"{what} R {job.tool.radius:g} of {Path(job.source or '').name}"


def rendered(outcome: Outcome, outputs, what: str, settings: Settings) -> dict:
    """``{output: bytes or str}`` of every output, by its suffix, titled by the operation,
    the ball and the part's file name (those :func:`operate` rendered beside the gate,
    when it was given the same ``outputs``)."""
    outputs = list(outputs)
    made = outcome.contents
    if made is not None and list(made) == outputs and what == outcome.what:
        return made
    return render_all(outcome.program, outputs, outcome.part, _title(outcome.program, what),
                      settings.processes, **(settings.gcode or {}))
