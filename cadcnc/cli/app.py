"""``cadcnc``: argparse subcommands, then one library call, then printing.

Errors the library raises on purpose (:class:`cadcnc.core.errors.CadcncError`) become one line
``cadcnc: error: <message>`` on stderr and the error's exit code (2 input, 3 geometry,
4 output; argparse usage errors are 2 as well; a refused gouge is 5). ``--debug`` shows the
traceback instead. Every option is defined once here or in the ``*_options`` modules; the
commands are imported on dispatch from the table of :mod:`cadcnc.cli.commands`.
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
from importlib.metadata import version

from cadcnc.core.errors import EXIT_INTERRUPTED, CadcncError  # light: the package loads OCCT lazily
from cadcnc.core.interrupts import sigint_deferred
from cadcnc.parallel import pool

from . import batch_options, finish_options, pencil_options, simulate_options, stream_options
from .commands import handler
from .operation_options import DEFAULT_FEED, DEFAULT_PERIOD, add_axis_options, add_max_cycles

UNITS = "Units: lengths mm, feed mm/min, period with a unit (4ms, 0.004s, 250us)."


def _common() -> argparse.ArgumentParser:
    common = argparse.ArgumentParser(add_help=False)
    g = common.add_argument_group("general")
    g.add_argument("-q", "--quiet", action="store_true", default=argparse.SUPPRESS,
                   help="no progress or summary on stderr/stdout (errors still shown)")
    g.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                   help="show the Python traceback on errors")
    return common


def _job_options(p, required: bool) -> None:
    """The machining job: faces, cutter, feed, period, start/end, edge."""
    p.add_argument("--faces", nargs=2, type=int, required=required, metavar=("I", "J"),
                   help="the two faces, numbered as `cadcnc faces` (FreeCAD's FaceN)")
    p.add_argument("--radius", required=required, metavar="R", help="ball radius, mm")
    p.add_argument("--allowance", default="0", metavar="C",
                   help="stock allowance left on both faces, mm (default 0)")
    p.add_argument("--feed", default=DEFAULT_FEED, metavar="F",
                   help=f"feed, mm/min (default {DEFAULT_FEED})")
    p.add_argument("--period", default=DEFAULT_PERIOD, metavar="T",
                   help=f"interpolation period with its unit: 4ms, 0.004s or 250us (default "
                        f"{DEFAULT_PERIOD}: a 0.1 mm step at {DEFAULT_FEED} mm/min)")
    p.add_argument("--start", metavar="X,Y,Z",
                   help="start point near the intersection, mm (default: the shared "
                        "concave edge's start)")
    p.add_argument("--end", metavar="X,Y,Z", help="end point, mm (needs --start)")
    p.add_argument("--edge", type=int, default=None, metavar="K",
                   help="only shared concave edge K (1, 2, ...; default: every edge)")
    p.add_argument("--stretch", type=int, default=None, metavar="N",
                   help="only feasible stretch N (1, 2, ... along the edge; default: every "
                        "stretch)")
    _flip_option(p)


def _flip_option(p) -> None:
    p.add_argument("--flip-material", action="store_true",
                   help="the material is on the other side of every face (a surface "
                        "model's side, or a solid's outside: docs/notes/surface_models.md)")


def _gouge_options(p, gate: bool = True) -> None:
    p.add_argument("--gouge-tolerance", default="0.001", metavar="MM",
                   help="the gouge limit: a ball cutting any face of the part deeper than "
                        "this fails (exit 5), mm (default 0.001)")
    if gate:
        p.add_argument("--allow-gouge", action="store_true",
                       help="write the path even when the whole-part check finds a gouge "
                            "(the exit code stays 5)")
        p.add_argument("--allow-partial", action="store_true",
                       help="write a path that stopped before its intended end (the exit "
                            "code stays 6)")


def _gcode_options(p) -> None:
    g = p.add_argument_group("G-code (.ngc output)")
    g.add_argument("--tolerance", metavar="MM",
                   help="chord tolerance: drop points whose removal moves the path less "
                        "than this, mm; also the G64 P blending tolerance and the print "
                        "precision (default: keep every point, 0.001 mm for G64 P and digits)")
    g.add_argument("--tool-tip", action="store_true",
                   help="program the ball's tip (Z - R) instead of its centre")
    g.add_argument("--clearance", "--safe-z", dest="clearance", metavar="Z",
                   help="height of rapid moves, mm in programmed coordinates (default: the "
                        "part's top plus 10 mm); --safe-z is an alias")
    g.add_argument("--spindle", metavar="RPM", type=float,
                   help="spindle speed; adds S<RPM> M3 ... M5 (default: none)")


def build_parser() -> argparse.ArgumentParser:
    common = _common()
    parser = argparse.ArgumentParser(
        prog="cadcnc", parents=[common],
        description="Ball-end cutter paths along the intersection of two faces of a STEP "
                    "part, by direct interpolation (Zhou et al. 1994). " + UNITS,
        epilog="Run `cadcnc demo` for a worked example; `cadcnc COMMAND --help` for details.")
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    def add(name, help_, description=None):
        return sub.add_parser(name, parents=[common], help=help_,
                              description=(description or help_) + " " + UNITS)

    p = add("faces", "list faces, neighbours and the concave pairs to follow",
            "List every face (number, kind, area in mm^2) and its neighbours with the edge "
            "class and material-side dihedral angle (deg); concave pairs are the candidates "
            "for an intersection path.")
    p.add_argument("step", metavar="PART.step")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    _flip_option(p)

    p = add("path", "compute a program and write it (.json, .csv, .ngc, .png, .glb)",
            "Compute the program of faces I and J: every feasible stretch of their shared "
            "concave edges cut by the ball, linked by retract, rapid and plunge; gate it "
            "against the whole part and write it; the format follows each output's suffix. "
            "Exit codes: docs/reliability.md (0 complete and verified, 2 bad input, 3 no "
            "feasible stretch, 5 gouge, 6 partial).")
    p.add_argument("step", metavar="PART.step", help="the part (STEP file, mm)")
    _job_options(p, required=True)
    p.add_argument("-o", "--output", action="append", required=True, metavar="OUT",
                   help="output file: .json (the program, version 2), .csv (a row per "
                        "cycle of every cut), .ngc (G-code), .png or .glb (a picture); "
                        "repeat for several")
    _gouge_options(p)
    _gcode_options(p)
    p.add_argument("--plunge-feed", metavar="F",
                   help="feed of the links' plunge moves, mm/min (default: the feed)")
    add_max_cycles(p)
    add_axis_options(p)

    pencil_options.add_parser(add, _flip_option, _gouge_options, _gcode_options)
    finish_options.add_parser(add, _flip_option, _gouge_options, _gcode_options)
    stream_options.add_parser(add, _flip_option, _gouge_options)
    batch_options.add_parser(add, parser)
    simulate_options.add_parser(add, _gouge_options)

    p = add("run", "execute an APT-like part program (PATH = P/[...])",
            "Execute an APT-like part program (grammar: docs/notes/apt.md). Prints a summary per "
            "path, streams the per-period increments, or writes outputs.")
    p.add_argument("program", metavar="PROGRAM.apt")
    p.add_argument("--stream", action="store_true",
                   help="print 'dx dy dz' (mm) per interpolation period to stdout")
    p.add_argument("-o", "--output", action="append", metavar="OUT",
                   help=".ngc: one program for all paths; .json/.csv: one file per path "
                        "(OUT-NAME.json when the program has several)")
    _gouge_options(p)
    _gcode_options(p)

    p = add("demo", "run the main job on a bundled part and write everything",
            "Compute the path around the boss of the bundled bspline_boss part (faces 4 and "
            "5, R 3 mm, 1500 mm/min, 4 ms), verify it, and write JSON, CSV, G-code, a "
            "verification report and a picture to a folder.")
    p.add_argument("--out", default="cadcnc-demo", metavar="DIR",
                   help="output folder (default: ./cadcnc-demo)")

    p = add("plot", "picture of a saved path (.png) or a 3-D scene (.glb)")
    p.add_argument("path_json", metavar="PATH.json",
                   help="a program written by `cadcnc path` (or a version 1 path)")
    p.add_argument("--part", metavar="PART.step",
                   help="the part (default: the STEP file recorded in the path)")
    p.add_argument("-o", "--output", required=True, metavar="OUT",
                   help=".png (matplotlib) or .glb (glTF scene)")

    p = add("verify", "check a path against OCCT (gouge gate for pipelines)",
            "Verify a path against geometry computed independently by OCCT: either compute it "
            "(PART.step --faces I J --radius R [--feed F --period T]) or read it (PATH.json "
            "[--part PART.step]). Exit 5 when the ball cuts the part deeper than "
            "--gouge-tolerance.")
    p.add_argument("input", metavar="PART.step|PATH.json")
    p.add_argument("--part", metavar="PART.step", help="the part of a saved PATH.json")
    _job_options(p, required=False)
    _gouge_options(p, gate=False)
    # the old spelling of --gouge-tolerance, kept so that scripts keep working
    p.add_argument("--tolerance", dest="gouge_tolerance", help=argparse.SUPPRESS)
    p.add_argument("--json", action="store_true", help="the report as JSON")
    return parser


def _version() -> str:
    try:
        return f"cadcnc {version('cadcnc')}"
    except Exception:  # noqa: BLE001 - not installed: fall back to the source tree's value
        return "cadcnc (version unknown)"


POINT_OPTIONS = ("--start", "--end", "--origin", "--axis", "--setups")


def _negative_points_joined(argv: list[str]) -> list[str]:
    """``--start -6,6,5`` as ``--start=-6,6,5`` and ``--axis -Z`` as ``--axis=-Z``:
    argparse takes a value that starts with a minus sign for an option."""
    out: list[str] = []
    for arg in argv:
        if out and out[-1] in POINT_OPTIONS and arg.startswith("-") and (
                arg[1:2].isdigit() or arg[1:2] in ".xyzXYZ"):
            out[-1] = f"{out[-1]}={arg}"
        else:
            out.append(arg)
    return out


def main(argv: list[str] | None = None, ending: bool = False) -> int:
    """Parse ``argv`` and run its command; its exit code. ``ending``: this process ends
    when the command does (the console program): what the imports make is then kept out
    of the garbage collector's walks, while they run and after (it lives to the end
    anyway)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser().parse_args(_negative_points_joined(argv))
    debug = getattr(args, "debug", False)
    args.quiet = getattr(args, "quiet", False)
    try:
        # importing the library (OCCT) takes ~1.5 s: `--help` and usage errors don't pay it;
        # Ctrl-C inside OCCT's C-extension import would surface as an ImportError
        with sigint_deferred():
            if getattr(args, "processes", 1) != 1:   # its imports run beside ours
                pool.start(args.processes)
            if ending:   # no collection meanwhile: what the imports make stays (0.1 s)
                gc.disable()
            try:
                run = handler(args.command)   # the library imported now (commands.py)
            finally:
                if ending:
                    gc.freeze()
                    gc.enable()
        return int(run(args) or 0)
    except KeyboardInterrupt:
        print("cadcnc: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # `cadcnc run --stream ... | head`: the reader left, fine
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except Exception as e:  # noqa: BLE001 - one line for the library's own errors
        if debug or not isinstance(e, CadcncError):
            raise
        print(f"cadcnc: error: {e}", file=sys.stderr)
        return e.exit_code


if __name__ == "__main__":
    sys.exit(main())
