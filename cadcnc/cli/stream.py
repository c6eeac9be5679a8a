"""``cadcnc stream``: a program as one position per servo period, at the planned feed.

Reads the machine (``--machine FILE.ini``, LinuxCNC's INI; default a Tormach PCNC 770),
plans the feed to its axis limits, re-runs every cut on the part with the planned feed
as the per-cycle override, gates every streamed position and chord against the whole
part, and only then writes ``.npy`` (N, 3) or ``.txt`` (halstreamer ``cfg=fff``)
atomically. With ``--hal`` the gated stream is then executed by LinuxCNC's HAL
(``streamer`` into one ``limit3`` per axis at the machine's limits, read back by
``halsampler``: :func:`cadcnc.controller.hal.run_hal_loop`). Exit 0 written (and, with
``--hal``, executed as streamed), 1 HAL could not start or run (its own text), 2 bad input
(INI, limits, feed), 3 the kernel could not re-run a cut, 5 the gate refused the stream,
6 the executed program fell short of the stream (a sample clipped by ``limit3`` or an
underrun within the program), 130 Ctrl-C (HAL unloaded).

:func:`stream_outputs` is the whole command after its arguments are read, for the other
commands' ``--stream OUT`` option.
"""

from __future__ import annotations

import io

from cadcnc.core.units import parse_feed, parse_length
from cadcnc.core.work_limits import MAX_STREAM_PERIODS

from .feedback import say_error

SUFFIXES = (".npy", ".txt")


def add_parser(add, flip, gouge) -> None:
    """Register ``stream`` with ``add(name, help, description)`` and the shared option
    groups of :mod:`cadcnc.cli.app` (flip-material, gouge gate)."""
    p = add("stream", "a program as one position per servo period, feed planned to the "
            "machine's limits",
            "Plan the feed of a program (written by path, pencil or finish) to the axes' "
            "velocity, acceleration and jerk limits, compute every period's position on "
            "the exact path, gate them against the part, and write them: .npy (N x 3 "
            "float64, mm) or .txt (one 'X Y Z' line per period, halstreamer cfg=fff).")
    p.add_argument("program", metavar="PROGRAM.json")
    p.add_argument("-o", "--output", action="append", metavar="OUT",
                   help=".npy or .txt; repeat for both (optional with --hal)")
    p.add_argument("--machine", metavar="FILE.ini",
                   help="LinuxCNC INI: [EMCMOT] SERVO_PERIOD, [TRAJ] LINEAR_UNITS, [AXIS_X/Y/Z] "
                        "MAX_VELOCITY, MAX_ACCELERATION, MAX_JERK (default: a Tormach "
                        "PCNC 770, docs/controller.md)")
    p.add_argument("--jerk", metavar="J",
                   help="jerk limit of every axis, mm/s^3, where the INI has no MAX_JERK "
                        "(LinuxCNC 2.9 has none); without --machine it replaces the default's")
    p.add_argument("--feed", metavar="F", help="replace the program's feed, mm/min")
    p.add_argument("--constant-feed", action="store_true",
                   help="stream at the programmed feed ignoring the limits (a comparison)")
    p.add_argument("--part", metavar="PART.step",
                   help="the part (default: the STEP file recorded in the program)")
    p.add_argument("--hal", action="store_true",
                   help="then execute the stream in LinuxCNC's HAL (streamer -> limit3 at "
                        "the machine's limits -> sampler; needs linuxcnc-uspace) and report "
                        "samples, underruns, executed - commanded, clipped samples (exit 6 "
                        "if any sample was clipped or underran)")
    p.add_argument("--max-periods", type=int, default=MAX_STREAM_PERIODS, metavar="N",
                   help=f"refuse a stream of more servo periods (default {MAX_STREAM_PERIODS}:"
                        " about 140 bytes a period while computed: 2.7 GB)")
    flip(p)
    gouge(p)


def machine_of(args):
    """The Machine of --machine / --jerk (InputError on a bad file or value)."""
    from dataclasses import replace

    from cadcnc.controller.machine import Machine, read_machine_ini

    jerk = None if args.jerk is None else parse_length(args.jerk, "jerk", allow_zero=False)
    if args.machine is not None:
        return read_machine_ini(args.machine, jerk,
                                warn=lambda text: say_error(f"cadcnc: warning: {text}"))
    m = Machine.default()
    return m if jerk is None else replace(m, max_jerk=(jerk,) * 3,
                                          source=m.source.split(",")[0] + f", jerk {jerk:g}")


def stream_command(args) -> int:
    import cadcnc
    from cadcnc.core.errors import InputError
    from cadcnc.io.output_set import OutputSet
    from cadcnc.io.program_json import read_program
    from cadcnc.verification.stream_check import check_program_on_part

    from .options import tolerances

    if not args.output and not args.hal:
        raise InputError("stream: give -o OUT (.npy or .txt), --hal, or both")
    if args.max_periods < 1:
        raise InputError(f"--max-periods must be at least 1, got {args.max_periods}")
    machine = machine_of(args)
    feed = None if args.feed is None else parse_feed(args.feed)
    tol = tolerances(args)
    program = read_program(args.program)
    source = args.part or program.job.source
    if not source:
        raise InputError(f"{args.program}: the program names no part: give --part PART.step")
    inputs = [args.program, source, args.machine]
    if args.output:   # every destination against every input before any work
        OutputSet(args.output, SUFFIXES, inputs=inputs)
    part = cadcnc.load_step(source, flip_material=args.flip_material)
    check_program_on_part(program, part, str(args.program), str(source), tol.gouge)
    return stream_outputs(program, part, machine, args.output or [], feed=feed,
                          planned=not args.constant_feed, tolerances=tol,
                          allow_gouge=args.allow_gouge, hal=args.hal, quiet=args.quiet,
                          name=str(args.program), inputs=inputs,
                          max_periods=args.max_periods)


def stream_outputs(program, part, machine, out, *, feed=None, planned=True, tolerances=None,
                   allow_gouge=False, hal=False, quiet=False, name="program",
                   inputs=(), max_periods=MAX_STREAM_PERIODS) -> int:
    """Stream ``program`` on ``part`` to ``machine`` and write it to ``out`` (a path or a
    list of paths, ``.npy`` / ``.txt``); optionally execute it in HAL. The exit code (see
    the module doc); raises the library's errors (InputError, GeometryError, HalError...).

    Before any work: every destination checked against ``inputs`` and the machine's INI,
    the periods estimated and refused over ``max_periods`` (exit 2). While it works: a
    heartbeat on stderr at least every 5 s (not ``quiet``); SIGTERM as Ctrl-C (130).
    Before anything is written: the positions about to be written checked against the
    machine's limits and the program's ends (:mod:`cadcnc.verification.stream_check`,
    exit 5 and nothing written or executed), then gated against the part.

    For ``path``, ``pencil`` and ``finish --stream OUT``: call it with the program they
    computed, the part, :func:`machine_of` of the arguments and OUT, after their own
    outputs are written."""
    from cadcnc.core.work_limits import sigterm_as_interrupt
    from cadcnc.core.work_limits import Ticker

    if hal:
        from cadcnc.controller.hal import HalError, hal_available

        missing = hal_available()
        if missing:
            raise HalError(f"--hal: HAL tools {missing} (install linuxcnc-uspace)")
    outs = [out] if isinstance(out, (str, bytes)) or hasattr(out, "__fspath__") else list(out)
    inputs = [i for i in inputs if i is not None] + [machine.source]
    report = None if quiet else say_error
    with sigterm_as_interrupt(), Ticker(report, "cadcnc: stream") as tick:
        return _stream(program, part, machine, outs, tick, feed=feed, planned=planned,
                       tolerances=tolerances, allow_gouge=allow_gouge, hal=hal, quiet=quiet,
                       name=name, inputs=inputs, max_periods=max_periods)


def _stream(program, part, machine, outs, tick, *, feed, planned, tolerances, allow_gouge,
            hal, quiet, name, inputs, max_periods) -> int:
    """:func:`stream_outputs` inside its heartbeat and SIGTERM handler."""
    from cadcnc.core.errors import EXIT_GOUGE, EXIT_OK, EXIT_PARTIAL
    from cadcnc.io.output_set import OutputSet
    from cadcnc.ops.stream_steppers import stepper_factory
    from cadcnc.core.tolerances import DEFAULT
    from cadcnc.verification import gate_program

    outputs = OutputSet(outs, SUFFIXES, inputs=inputs) if outs else None
    tick.stage = "planning the feed"
    stream = _planned_stream(program, machine, stepper_factory(part), tick, feed=feed,
                             planned=planned, max_periods=max_periods, quiet=quiet)
    tick.stage = "checking the stream against the machine's limits"
    contents = _contents(stream.positions, outputs)
    problems = _limits_broken(program, machine, stream.positions, contents)
    if problems:
        for line in problems[:8]:
            say_error(f"cadcnc: stream: {line}")
        say_error("cadcnc: stream: over the machine's limits: nothing written"
                  + (" or executed" if hal else "") + " (exit 5)")
        return EXIT_GOUGE
    tick.stage = "gating the stream against the part"
    gate = gate_program(program, part, tolerances or DEFAULT,
                        moves=stream.segment_moves(program))
    if not gate.ok and not allow_gouge:
        say_error(f"cadcnc: stream: {gate.message}; nothing written (--allow-gouge writes it)")
        return EXIT_GOUGE
    if outputs is not None:
        tick.stage = "writing"
        outputs.write(contents)
    if not quiet:
        print(summary_text(stream, name))
        if outputs is not None:
            print(f"  wrote      {', '.join(map(str, outputs.destinations))}")
    code = EXIT_OK if gate.ok else EXIT_GOUGE
    if hal:
        from cadcnc.controller.hal import run_hal_loop, summary as hal_report

        tick.stage = "executing in HAL"
        result = run_hal_loop(stream.positions, machine, limits="machine")
        fell_short = result.clipped or result.underruns or result.overruns
        if not quiet or fell_short:
            print(hal_report(result))
        if fell_short:
            say_error(f"cadcnc: stream: HAL executed less than the stream: {result.clipped} "
                      f"samples clipped by limit3, {result.underruns} underruns, "
                      f"{result.overruns} samples lost")
            code = max(code, EXIT_PARTIAL)
    return code


def _planned_stream(program, machine, steppers, tick, *, feed, planned, max_periods, quiet):
    """The stream, its periods estimated and bounded before the positions are computed,
    progress reported (the plan is made once here to count the periods first)."""
    from cadcnc.controller.stream import stream_program
    from cadcnc.core.work_limits import refuse_over

    said = []

    def estimate(total: int) -> None:
        refuse_over("the stream", total, max_periods, "servo periods",
                    "raise the feed or the machine's limits, or give --max-periods N "
                    "(each 24 bytes in memory)")
        if not quiet and not said:
            say_error(f"cadcnc: stream: {total} periods of {machine.period * 1e3:g} ms "
                      f"(cycle {total * machine.period:.3f} s) to compute")
        said.append(total)
        tick.stage = f"streaming {total} periods"

    from cadcnc.controller.feed_plan import plan_feed
    from cadcnc.controller.pieces import pieces_of

    estimate(plan_feed(pieces_of(program, machine, feed), machine, planned).periods)

    def progress(done: int, total: int, what: str) -> None:
        tick.stage = f"streaming: {done}/{total} {what}"

    return stream_program(program, machine, steppers, feed=feed, planned=planned,
                          max_periods=max_periods, progress=progress)


def _contents(positions, outputs) -> dict:
    """``{destination: bytes or str}`` of every output (.npy, .txt)."""
    import numpy as np

    from cadcnc.controller.stream import stream_text

    contents = {}
    for dest in (outputs.destinations if outputs is not None else ()):
        if dest.suffix.lower() == ".npy":
            buf = io.BytesIO()
            np.save(buf, positions)
            contents[dest] = buf.getvalue()
        else:
            contents[dest] = stream_text(positions)
    return contents


def _limits_broken(program, machine, positions, contents) -> list[str]:
    """What breaks the machine's limits or misses the program's ends: in the positions,
    and in each .txt's numbers as written (9 decimals)."""
    import numpy as np

    from cadcnc.verification.stream_check import check_stream

    limits = (machine.max_velocity, machine.max_acceleration, machine.max_jerk)
    ends = (program.segments[0].points[0], program.segments[-1].points[-1])
    found = check_stream(positions, machine.period, limits, *ends).problems
    for dest, text in contents.items():
        if isinstance(text, str) and not found:
            rows = np.fromstring(text, dtype=np.float64, sep=" ").reshape(-1, 3)
            found = check_stream(rows, machine.period, limits, *ends, what=str(dest)).problems
    return found


def summary_text(stream, name: str) -> str:
    """The stream's summary for the user: time, periods, shares of the limits."""
    s = stream.summary()
    kind = "planned feed" if stream.plan.planned else "constant feed (limits ignored)"
    lines = [f"{name}: {kind}, machine {s['machine'] or 'default'}",
             f"  cycle      {s['cycle_time_s']:.3f} s, {s['periods']} periods of "
             f"{s['period_s'] * 1e3:g} ms; at the programmed feed {s['programmed_time_s']:.3f} "
             f"s, lost to the limits {s['time_lost_s']:.3f} s",
             f"  cuts       {s['kernel_cuts']} re-run by the kernel, {s['hermite_cuts']} "
             "interpolated from their points (roll-over arcs)"]
    for what in ("velocity", "acceleration", "jerk"):
        shares = s[f"max_{what}_share"]
        lines.append(f"  max {what:<12} " + ", ".join(
            f"{axis} {100 * v:.1f} %" for axis, v in shares.items()) + " of the limit")
    return "\n".join(lines)
