"""A program as one position per servo period: planned, checked, gated, written, and
optionally executed in LinuxCNC's HAL (``cadcnc stream``, and the operations' ``--stream``).

Before any work: every destination checked against the inputs and the machine's INI, the
periods estimated and refused over ``max_periods`` (exit 2). Before anything is written:
the positions checked against the machine's limits and the program's ends
(:mod:`cadcnc.verification.stream_check`, exit 5, nothing written or executed), then gated
against the part (exit 5 unless ``allow_gouge``). With ``hal`` the gated stream is then run
by :func:`cadcnc.controller.hal.run_hal_loop`: exit 6 when the machine executed less.
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field

import numpy as np

from ..controller.hal import HalError, hal_available, run_hal_loop
from ..controller.hal import summary as hal_summary
from ..controller.stream import stream_program, stream_text
from ..core.errors import EXIT_GOUGE, EXIT_OK, EXIT_PARTIAL, InputError
from ..core.tolerances import DEFAULT, STREAM_BLEND
from ..core.units import check_number
from ..core.work_limits import MAX_STREAM_PERIODS, Ticker, refuse_over, sigterm_as_interrupt
from ..geometry.part import load_step
from ..geometry.setup import setup_part
from ..io.output_set import OutputSet
from ..io.program_json import read_program_and_setup
from ..ops.stream_steppers import stepper_factory
from ..verification import gate_program
from ..verification.stream_check import StreamChecker, check_program_on_part, check_stream

SUFFIXES = (".npy", ".txt")
WRITE_ROWS = 1 << 15   # periods printed or copied to a file at a time (a few MB)


@dataclass
class StreamRun:
    """What a stream left: the exit ``code``, ``messages`` for the user (stderr), the
    stream (None when refused before it was computed), the files ``written``, and the HAL
    run's report (None without HAL) with ``fell_short``: it executed less than the stream."""

    code: int
    messages: list[str] = field(default_factory=list)
    stream: object = None
    written: list[str] = field(default_factory=list)
    hal_report: str | None = None
    fell_short: bool = False


def stream_saved(program_file, part_file, machine, outputs, *, ini=None, tolerances=DEFAULT,
                 flip_material: bool = False, say=None, **options) -> StreamRun:
    """Stream the program saved in ``program_file`` on its part (``part_file``, default
    the STEP file it records) to ``outputs`` (.npy, .txt); ``ini``: the machine's INI
    file (an input no output may overwrite); ``options``: as :func:`stream_to`."""
    program, setup = read_program_and_setup(program_file)   # in its work coordinates
    source = part_file or program.job.source
    if not source:
        raise InputError(f"{program_file}: the program names no part: give --part PART.step")
    inputs = [program_file, source, ini]
    if outputs:   # every destination against every input before any work
        OutputSet(outputs, SUFFIXES, inputs=inputs)
    part = load_step(source, flip_material=flip_material)
    if setup is not None:   # a program of another tool axis: the part turned as it was
        part = setup_part(part, setup)
    check_program_on_part(program, part, str(program_file), str(source), tolerances.gouge)
    return stream_to(program, part, machine, outputs, tolerances=tolerances, say=say,
                     inputs=inputs, **options)


def stream_to(program, part, machine, outputs, *, feed=None, planned=True, tolerances=None,
              allow_gouge=False, hal=False, say=None, inputs=(),
              max_periods=MAX_STREAM_PERIODS, blend=STREAM_BLEND) -> StreamRun:
    """Stream ``program`` on ``part`` to ``machine`` and write it to ``outputs`` (a list
    of paths, .npy / .txt); optionally execute it in HAL (module doc). ``say``: progress
    on stderr (a heartbeat at least every 5 s), or None; SIGTERM counts as Ctrl-C.
    ``blend`` (mm): the links' corners rounded within it where that is faster (0: exact
    stops; a rounded link the gate refuses keeps its exact corners).
    Raises the library's errors (InputError, GeometryError, HalError ...)."""
    blend = check_number("blend", blend, "mm", allow_zero=True)
    if hal:
        missing = hal_available()
        if missing:
            raise HalError(f"--hal: HAL tools {missing} (install linuxcnc-uspace)")
    inputs = [i for i in inputs if i is not None] + [machine.source]
    with sigterm_as_interrupt(), Ticker(say, "cadcnc: stream") as tick:
        return _stream(program, part, machine, list(outputs), tick, feed=feed,
                       planned=planned, tolerances=tolerances, allow_gouge=allow_gouge,
                       hal=hal, say=say, inputs=inputs, max_periods=max_periods,
                       blend=blend)


def _stream(program, part, machine, outs, tick, *, feed, planned, tolerances, allow_gouge,
            hal, say, inputs, max_periods, blend) -> StreamRun:
    """:func:`stream_to` inside its heartbeat and SIGTERM handler."""
    outputs = OutputSet(outs, SUFFIXES, inputs=inputs) if outs else None
    exact: frozenset[int] = frozenset()
    while True:   # a rounded link the gate refuses: streamed again with exact corners
        tick.stage = "planning the feed"
        stream = _planned_stream(program, machine, stepper_factory(part), tick, feed=feed,
                                 planned=planned, max_periods=max_periods, say=say,
                                 blend=blend if planned else 0.0, exact=exact,
                                 scratch=_scratch(outputs))
        tick.stage = "checking the stream against the machine's limits"
        problems = _limits_broken(program, machine, stream.positions)
        if problems:
            return _over_limits(problems, hal)
        tick.stage = "gating the stream against the part"
        gate = gate_program(program, part, tolerances or DEFAULT,
                            moves=stream.segment_moves(program))
        refused = _refused_links(program, gate) & stream.rounded - exact
        if gate.ok or not refused:
            break
        exact |= refused
        stream = gate = None   # (their positions' scratch file freed before the next)
        if say is not None:
            say(f"cadcnc: stream: the gate refused {len(refused)} rounded link(s): "
                "streamed again with their exact corners")
    if not gate.ok and not allow_gouge:
        return StreamRun(EXIT_GOUGE, [f"cadcnc: stream: {gate.message}; nothing written "
                                      "(--allow-gouge writes it)"])
    done = StreamRun(EXIT_OK if gate.ok else EXIT_GOUGE, stream=stream)
    if outputs is not None:
        # written WRITE_ROWS periods at a time, each .txt's numbers as printed checked
        # again on the way: a refusal leaves nothing written
        tick.stage = "writing (each .txt's numbers checked as printed)"
        try:
            outputs.write(_contents(program, machine, stream.positions, outputs))
        except _PrintedOver as over:
            return _over_limits(over.problems, hal)
        done.written = [str(d) for d in outputs.destinations]
    if hal:
        tick.stage = "executing in HAL"
        result = run_hal_loop(stream.positions, machine, limits="machine")
        done.hal_report = hal_summary(result)
        done.fell_short = bool(result.clipped or result.underruns or result.overruns)
        if done.fell_short:
            done.messages.append(
                f"cadcnc: stream: HAL executed less than the stream: {result.clipped} "
                f"samples clipped by limit3, {result.underruns} underruns, "
                f"{result.overruns} samples lost")
            done.code = max(done.code, EXIT_PARTIAL)
    return done


def _refused_links(program, gate) -> frozenset[int]:
    """Segment indices of the links the gate found failing: those before each cut whose
    link moves fail, and the final retract when the last cut's do (as the gate assigns
    them: :func:`cadcnc.verification.program_gate.cut_moves`)."""
    out, before, cut = set(), [], 0
    for k, seg in enumerate(program.segments):
        if seg.kind == "link":
            before.append(k)
            continue
        if cut < len(gate.link_failed) and gate.link_failed[cut]:
            out.update(before)
        before, cut = [], cut + 1
    if before and gate.link_failed and gate.link_failed[-1]:
        out.update(before)
    return frozenset(out)


def _scratch(outputs) -> str | None:
    """The folder of a long stream's positions file: the first output's (the disk that
    will hold the stream anyway), else the system's temporary folder."""
    return None if outputs is None else str(outputs.destinations[0].parent)


def _planned_stream(program, machine, steppers, tick, *, feed, planned, max_periods, say,
                    blend=0.0, exact=frozenset(), scratch=None):
    """The stream, its periods counted and bounded from its plan before the positions are
    computed (``stream_program``'s ``on_plan``), progress reported."""

    def counted(plan) -> None:
        total = plan.periods
        refuse_over("the stream", total, max_periods, "servo periods",
                    "raise the feed or the machine's limits, or give --max-periods N "
                    "(each 24 bytes of scratch file beside the first output, and of each "
                    ".npy; about 40 in a .txt)")
        if say is not None:
            say(f"cadcnc: stream: {total} periods of {machine.period * 1e3:g} ms "
                f"(cycle {total * machine.period:.3f} s) to compute")
        tick.stage = f"streaming {total} periods"

    def progress(done: int, total: int, what: str) -> None:
        tick.stage = f"streaming: {done}/{total} {what}"

    return stream_program(program, machine, steppers, feed=feed, planned=planned,
                          max_periods=max_periods, progress=progress, blend=blend,
                          exact=exact, on_plan=counted, scratch=scratch)


class _PrintedOver(Exception):
    """A .txt's numbers as printed break the limits or miss the ends (``problems``)."""

    def __init__(self, problems: list[str]):
        super().__init__(problems[0])
        self.problems = problems


def _contents(program, machine, positions, outputs) -> dict:
    """``{destination: chunks}`` of every output (.npy, .txt), made as they are written
    (a file's bytes are never all in memory)."""
    return {dest: _npy_chunks(positions) if dest.suffix.lower() == ".npy"
            else _txt_chunks(program, machine, positions, str(dest))
            for dest in outputs.destinations}


def _npy_chunks(positions: np.ndarray):
    """The bytes ``np.save`` writes for ``positions``: its header, then its rows."""
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, np.lib.format.header_data_from_array_1_0(
        positions))
    yield header.getvalue()
    for a in range(0, len(positions), WRITE_ROWS):
        yield np.ascontiguousarray(positions[a:a + WRITE_ROWS]).tobytes()


def _txt_chunks(program, machine, positions: np.ndarray, name: str):
    """:func:`stream_text` of ``positions`` a block at a time, each block's numbers as
    printed checked against the limits and ends (:class:`_PrintedOver` after the last)."""
    limits, ends = _limits_and_ends(program, machine)
    checker = StreamChecker(machine.period, limits, name)
    for a in range(0, len(positions), WRITE_ROWS):
        text = stream_text(positions[a:a + WRITE_ROWS])
        checker.feed(np.fromstring(text, dtype=np.float64, sep=" ").reshape(-1, 3))
        yield text
    problems = checker.result(*ends).problems
    if problems:
        raise _PrintedOver(problems)


def _over_limits(problems: list[str], hal: bool) -> StreamRun:
    """The refusal of a stream over the machine's limits (exit 5, nothing written)."""
    return StreamRun(EXIT_GOUGE, [f"cadcnc: stream: {line}" for line in problems[:8]]
                     + ["cadcnc: stream: over the machine's limits: nothing written"
                        + (" or executed" if hal else "") + " (exit 5)"])


def _limits_and_ends(program, machine) -> tuple[tuple, tuple]:
    """The machine's (velocity, acceleration, jerk) limits and the program's ends."""
    return ((machine.max_velocity, machine.max_acceleration, machine.max_jerk),
            (program.segments[0].points[0], program.segments[-1].points[-1]))


def _limits_broken(program, machine, positions) -> list[str]:
    """What breaks the machine's limits or misses the program's ends in ``positions``
    ((N, 3) mm)."""
    limits, ends = _limits_and_ends(program, machine)
    return check_stream(positions, machine.period, limits, *ends).problems
