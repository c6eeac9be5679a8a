"""The options the operation commands (``path``, ``pencil``, ``finish``) share: feed,
period, outputs, work limit, processes, setup and ``--stream``."""

from __future__ import annotations

from cadcnc.core.job import DEFAULT_FEED as FEED
from cadcnc.core.job import DEFAULT_PERIOD as PERIOD
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
    p.add_argument("--jobs", dest="processes", type=int, default=None, metavar="N",
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

