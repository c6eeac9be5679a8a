"""What the operation commands (``path``, ``pencil``, ``finish``) share: their feed and
output options, and the command itself: options to a Job, one library call, the library's
verdict, the summary, the outputs written all at once, the library's exit code."""

from __future__ import annotations

from pathlib import Path

from cadcnc.core.job import DEFAULT_FEED as FEED, DEFAULT_PERIOD as PERIOD
from cadcnc.core.work_limits import MAX_CYCLES

DEFAULT_FEED = f"{FEED:g}"  # the job's defaults as the options' text
DEFAULT_PERIOD = f"{PERIOD * 1000:g}ms"
OUTPUT_HELP = ("output: .json (the program), .csv (a row per cycle of every cut), .ngc "
               "(G-code), .png or .glb (a picture); repeat for several")


def add_operation_options(p, allowance_help: str) -> None:
    """The options every operation takes: --allowance, --feed, --period, --plunge-feed
    and -o (repeatable)."""
    p.add_argument("--allowance", default="0", metavar="C",
                   help=f"{allowance_help}, mm (default 0)")
    p.add_argument("--feed", default=DEFAULT_FEED, metavar="F",
                   help=f"feed, mm/min (default {DEFAULT_FEED})")
    p.add_argument("--period", default=DEFAULT_PERIOD, metavar="T",
                   help=f"interpolation period with its unit (default {DEFAULT_PERIOD}: "
                        f"a {FEED * PERIOD / 60:g} mm step at {DEFAULT_FEED} mm/min)")
    p.add_argument("--plunge-feed", metavar="F",
                   help="feed of the plunges in the links, mm/min (default: --feed)")
    p.add_argument("-o", "--output", action="append", required=True, metavar="OUT",
                   help=OUTPUT_HELP)
    add_max_cycles(p)
    add_axis_options(p)


def add_axis_options(p) -> None:
    """--axis and --origin: the setup (docs/setups.md)."""
    g = p.add_argument_group("setup (docs/setups.md)")
    g.add_argument("--axis", metavar="AXIS",
                   help="tool axis in part coordinates, from the ball up the shank: +Z "
                        "(default), -Z, +X, -X, +Y, -Y or a vector x,y,z; the G-code is in "
                        "the setup's work coordinates")
    g.add_argument("--origin", metavar="X,Y,Z",
                   help="work zero in part coordinates, mm (default: the centre of the "
                        "part's top seen along the axis; with +Z, the part's origin)")


def add_max_cycles(p) -> None:
    """--max-cycles (the work limit, docs/reliability.md) and the --stream options."""
    p.add_argument("--max-cycles", type=int, default=MAX_CYCLES, metavar="N",
                   help=f"interpolation cycles the program may need, estimated before "
                        f"computing and refused over it (default {MAX_CYCLES})")
    p.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="processes: pencil's corners, finishing's planes and the gouge "
                        "gate's cuts run on N cores (default: all; 1: one process); the "
                        "outputs are the same whatever N")
    g = p.add_argument_group("stream (docs/controller.md)")
    g.add_argument("--stream", action="append", metavar="OUT",
                   help="also write the program as one position per servo period, its feed "
                        "planned to the machine's limits: .npy or .txt (as `cadcnc stream`); "
                        "only a complete, verified program is streamed")
    g.add_argument("--machine", metavar="FILE.ini",
                   help="the machine's LinuxCNC INI for --stream (default: a Tormach PCNC 770)")
    g.add_argument("--jerk", metavar="J", help="jerk limit of every axis for --stream, mm/s^3")



def operation_command(args, what: str, job_of, *, progress=None,
                      times: dict | None = None) -> int:
    """Run one operation from the command line (module doc), its worker processes
    (``--jobs``) ended when it returns."""
    from cadcnc.parallel.pool import kept_pools

    with kept_pools():
        return _operation(args, what, job_of, progress=progress, times=times)


def _operation(args, what: str, job_of, *, progress=None, times: dict | None = None) -> int:
    """Run one operation from the command line (module doc). ``job_of(args, source)``
    builds its Job; ``progress``: the operation's progress callback; ``times``: per-stage
    seconds (pencil)."""
    from cadcnc.batch.operate import operate, rendered
    from cadcnc.geometry.setup import setup_in
    from cadcnc.io.output_set import OutputSet
    from cadcnc.io.outputs import SUFFIXES

    from .feedback import say_error, stage_progress
    from .options import settings_of

    outputs = OutputSet(args.output, SUFFIXES, inputs=[args.step])  # checked before computing
    machine = None
    if getattr(args, "stream", None):
        from cadcnc.io.output_set import check_destination

        from .stream import SUFFIXES as STREAM_SUFFIXES, machine_of

        for out in args.stream:
            check_destination(out, STREAM_SUFFIXES, [args.step])
        machine = machine_of(args)
    job = job_of(args, args.step)
    settings = settings_of(args)
    done = operate(args.step, job, what, settings, progress=progress, times=times,
                   gate_progress=stage_progress(args, f"{what}: gouge check", after_s=1.0))
    program, part, verdict = done.program, done.part, done.verdict
    for line in verdict.messages:
        say_error(line)
    if not args.quiet:
        print(program.summary(Path(args.step).name))
        if setup_in(part) is not None:
            print("  setup      " + "; ".join(setup_in(part).describe()))
        print("  verdict    " + ("written" if verdict.write else "nothing written") + (
            "" if verdict.code == 0 else f" (exit {verdict.code}: see the message above)"))
        staged = "" if not times else "; " + ", ".join(f"{k} {v:.1f} s"
                                                       for k, v in times.items())
        print(f"  time       computed in {done.seconds_computed:.1f} s, gated in "
              f"{done.seconds_gated:.1f} s{staged}")
    if verdict.write:
        outputs.write(rendered(done, args.output, done.what, settings))
        if not args.quiet:
            print(f"  wrote      {', '.join(args.output)}")
    if machine is not None:
        if verdict.code != 0:
            say_error(f"cadcnc: {done.what}: not streamed: only a complete, verified program is")
            return verdict.code
        from .stream import stream_outputs

        return stream_outputs(program, part, machine, args.stream, tolerances=job.tolerances,
                              quiet=args.quiet, name=Path(args.step).name, inputs=[args.step])
    return verdict.code
