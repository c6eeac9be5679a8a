"""``cadcnc stream``: a program as one position per servo period, at the planned feed.

Reads the machine (``--machine FILE.ini``, LinuxCNC's INI; default a Tormach PCNC 770),
plans the feed to its axis limits, re-runs every cut on the part with the planned feed
as the per-cycle override, gates every streamed position and chord against the whole
part, and only then writes ``.npy`` (N, 3) or ``.txt`` (halstreamer ``cfg=fff``)
atomically. Exit 0 written, 2 bad input (INI, limits, feed), 3 the kernel could not
re-run a cut, 5 the gate refused the stream.
"""

from __future__ import annotations

import io

from cadcnc.units import parse_feed, parse_length

from .feedback import say_error

SUFFIXES = (".npy", ".txt")
GOUGE_REFUSED = 5


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
    p.add_argument("-o", "--output", action="append", required=True, metavar="OUT",
                   help=".npy or .txt; repeat for both")
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
    flip(p)
    gouge(p)


def machine_of(args):
    """The Machine of --machine / --jerk (InputError on a bad file or value)."""
    from dataclasses import replace

    from cadcnc.controller.machine import Machine, read_machine_ini

    jerk = None if args.jerk is None else parse_length(args.jerk, "jerk", allow_zero=False)
    if args.machine is not None:
        return read_machine_ini(args.machine, jerk)
    m = Machine.default()
    return m if jerk is None else replace(m, max_jerk=(jerk,) * 3,
                                          source=m.source.split(",")[0] + f", jerk {jerk:g}")


def stream_command(args) -> int:
    import numpy as np

    import cadcnc
    from cadcnc.controller.stream import stream_program, stream_text
    from cadcnc.errors import InputError
    from cadcnc.io.output_set import OutputSet
    from cadcnc.io.program_json import read_program
    from cadcnc.ops.stream_steppers import stepper_factory
    from cadcnc.verification import gate_program

    from .options import tolerances

    outputs = OutputSet(args.output, SUFFIXES, inputs=[args.program])
    machine = machine_of(args)
    feed = None if args.feed is None else parse_feed(args.feed)
    tol = tolerances(args)
    program = read_program(args.program)
    source = args.part or program.job.source
    if not source:
        raise InputError(f"{args.program}: the program names no part: give --part PART.step")
    part = cadcnc.load_step(source, flip_material=args.flip_material)
    stream = stream_program(program, machine, stepper_factory(part), feed=feed,
                            planned=not args.constant_feed)
    gate = gate_program(program, part, tol, moves=stream.segment_moves(program))
    if not gate.ok and not args.allow_gouge:
        say_error(f"cadcnc: stream: {gate.message}; nothing written (--allow-gouge writes it)")
        return GOUGE_REFUSED
    contents = {}
    for out in outputs.destinations:
        if out.suffix.lower() == ".npy":
            buf = io.BytesIO()
            np.save(buf, stream.positions)
            contents[out] = buf.getvalue()
        else:
            contents[out] = stream_text(stream.positions)
    outputs.write(contents)
    if not args.quiet:
        print(summary_text(stream, args.program))
        print(f"  wrote      {', '.join(map(str, outputs.destinations))}")
    return 0 if gate.ok else GOUGE_REFUSED


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
