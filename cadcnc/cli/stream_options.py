"""``cadcnc stream``'s options: a program as one position per servo period, at the planned
feed (the command: :func:`cadcnc.cli.stream_command.stream`; the run:
:mod:`cadcnc.pipeline.streaming`).

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
"""

from __future__ import annotations

from cadcnc.core.tolerances import STREAM_BLEND
from cadcnc.core.work_limits import MAX_STREAM_PERIODS


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
    p.add_argument("--blend", metavar="MM", default=str(STREAM_BLEND),
                   help="round each link's corners within MM where that streams faster "
                        f"(default {STREAM_BLEND:g}; 0: exact stops as programmed); cuts, "
                        "and the corners where a link meets a cut, are never rounded; a "
                        "rounded link the gate refuses keeps its exact corners")
    p.add_argument("--part", metavar="PART.step",
                   help="the part (default: the STEP file recorded in the program)")
    p.add_argument("--hal", action="store_true",
                   help="then execute the stream in LinuxCNC's HAL (streamer -> limit3 at "
                        "the machine's limits -> sampler; needs linuxcnc-uspace) and report "
                        "samples, underruns, executed - commanded, clipped samples (exit 6 "
                        "if any sample was clipped or underran)")
    p.add_argument("--max-periods", type=int, default=MAX_STREAM_PERIODS, metavar="N",
                   help=f"refuse a stream of more servo periods (default {MAX_STREAM_PERIODS}:"
                        " 5.6 h at 1 ms; 24 bytes a period of scratch file)")
    flip(p)
    gouge(p)
