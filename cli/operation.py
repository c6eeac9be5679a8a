"""What the operation commands (``pencil``, ``finish``) share: their feed and output
options, and the end of the command (cut back, gate the whole program, summary, write)."""

from __future__ import annotations

import csv
import io
from pathlib import Path

from cadcnc.errors import InputError  # light: OCCT is imported inside the functions
from cadcnc.job import DEFAULT_FEED as FEED, DEFAULT_PERIOD as PERIOD

SUFFIXES = (".json", ".ngc", ".csv", ".png", ".glb")
DEFAULT_FEED = f"{FEED:g}"  # the job's defaults as the options' text
DEFAULT_PERIOD = f"{PERIOD * 1000:g}ms"


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
                   help="output: .json, .ngc, .csv, .png or .glb; repeat for several")


def program_csv(program) -> str:
    """One row per cut point: segment number (1-based among all segments), faces, x y z."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["segment", "face_i", "face_j", "x_mm", "y_mm", "z_mm"])
    for k, seg in enumerate(program.segments, 1):
        if seg.kind != "cut":
            continue
        i, j = seg.path.faces
        for p in seg.points:
            w.writerow([k, i, j, f"{p[0]:.6f}", f"{p[1]:.6f}", f"{p[2]:.6f}"])
    return buf.getvalue()


def gate_and_write(args, program, part, outputs, what: str, title: str, join: float,
                   summary) -> int:
    """The end of an operation's command: cut gouging cuts back (unless --allow-gouge),
    gate the whole program as written, print ``summary(program)``, write the outputs by
    suffix; returns the exit code (0, 5 gouge, 6 partial)."""
    from cadcnc.io.program_gcode import program_ngc
    from cadcnc.io.program_json import program_json
    from cadcnc.io.program_plot import program_picture_bytes
    from cadcnc.ops.path.pair_program import safe_height
    from cadcnc.verification.cut_back import cut_back

    from .options import program_gcode_options
    from .program_commands import judge_program

    gopts = program_gcode_options(args)
    if not args.allow_gouge:  # a gouging cut is cut back and listed, not the program lost
        program = cut_back(program, part, safe_height(part, program.job), join)
        if not program.cuts:
            raise InputError(f"{args.step}: every cut gouges the part: "
                             f"{skipped_line(program)}")
    ngc = program_ngc(program, title=title, **gopts)
    write, code = judge_program(args, program, part, what, gopts)
    if not args.quiet:
        print(summary(program))
    if not write:
        return code
    contents = {}
    for out in args.output:
        suffix = Path(out).suffix.lower()
        contents[out] = (program_json(program) if suffix == ".json" else ngc
                         if suffix == ".ngc" else program_csv(program) if suffix == ".csv"
                         else program_picture_bytes(program, part, out, title))
    outputs.write(contents)
    if not args.quiet:
        print(f"  wrote      {', '.join(args.output)}")
    return code


def skipped_line(program) -> str:
    """Skipped corners or passes counted by reason: "2 no_fit, 1 tangent"."""
    counts: dict[str, int] = {}
    for s in program.skipped:
        counts[s.reason] = counts.get(s.reason, 0) + 1
    return ", ".join(f"{n} {r}" for r, n in sorted(counts.items()))


