"""``cadcnc finish``: raster finishing of selected faces in one program, gated, written.

Options are defined here (registered by :mod:`cadcnc.cli.app` with :func:`add_parser`).
Exit codes as ``pencil``: 0 for a complete program that passed the gouge gate (every cut,
then every move of the whole program, links included, as written), 5 a gouge, 6 partial
(a cut stopped short), 2 bad input, with ``--allow-gouge`` / ``--allow-partial`` to write
anyway.
"""

from __future__ import annotations

import time
from pathlib import Path

from cadcnc.errors import InputError  # light: OCCT is imported in finish_command
from cadcnc.units import parse_duration, parse_feed, parse_length

from .feedback import say_error
from .operation import SUFFIXES, add_operation_options, gate_and_write, skipped_line

PROGRESS_EVERY_S = 1.0  # s between two progress lines on stderr


def add_parser(add, job_flip, gouge, gcode) -> None:
    """Register ``finish`` with ``add(name, help, description)`` and the shared option
    groups of :mod:`cadcnc.cli.app` (flip-material, gouge gate, G-code)."""
    p = add("finish", "raster-finish selected faces (guide-plane passes) in one program",
            "Cut raster passes over the selected faces: the ball (R' = R + C) touches the "
            "faces while its centre stays on vertical guide planes at --angle to X, spaced "
            "by --stepover or so that the scallop stays within --scallop; zigzag or one-way, "
            "linked; gate the whole program and write it: .json (program), .ngc, .csv (a "
            "row per cut point), .png or .glb (picture). Exit 0 complete and verified, 2 "
            "bad input, 5 gouge, 6 partial.")
    p.add_argument("step", metavar="PART.step", help="the part (STEP file, mm)")
    p.add_argument("--faces", nargs="+", type=int, required=True, metavar="N",
                   help="the faces to finish, numbered as `cadcnc faces`")
    p.add_argument("--radius", required=True, metavar="R", help="ball radius, mm")
    spacing = p.add_mutually_exclusive_group(required=True)
    spacing.add_argument("--stepover", metavar="S", help="distance between the passes' "
                         "guide planes, mm")
    spacing.add_argument("--scallop", metavar="H", help="largest scallop height, mm: the "
                         "planes' spacing follows the faces' curvature and slope")
    p.add_argument("--angle", default="0", metavar="A",
                   help="direction of the passes, degrees from +X (default 0)")
    p.add_argument("--pattern", choices=("zigzag", "oneway"), default="zigzag",
                   help="zigzag (default: every other pass reversed, staying down where the "
                        "move is verified clear) or oneway (every pass the same way, "
                        "retracting between)")
    add_operation_options(p, "stock allowance left on the faces")
    job_flip(p)
    gouge(p)
    gcode(p)


def _angle(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise InputError(f"--angle: expected degrees, got {text!r}") from None


def finish_command(args) -> int:
    import cadcnc
    from cadcnc.io.output_set import OutputSet
    from cadcnc.ops.finish.finish import JOIN, finish

    from .options import clearance, tolerances

    outputs = OutputSet(args.output, SUFFIXES, inputs=[args.step])
    radius = parse_length(args.radius, "radius", allow_zero=False)
    allowance = parse_length(args.allowance, "allowance")
    spacing = dict(stepover=None if args.stepover is None else parse_length(
        args.stepover, "stepover", allow_zero=False), scallop=None if args.scallop is None
        else parse_length(args.scallop, "scallop", allow_zero=False))
    feed, period = parse_feed(args.feed), parse_duration(args.period)
    tol = tolerances(args)
    t0 = time.monotonic()
    part = cadcnc.load_step(args.step, flip_material=args.flip_material)
    for n in args.faces:
        part.face(n)  # face numbers checked before anything is computed
    program = finish(part, args.faces, radius=radius, allowance=allowance,
                     angle=_angle(args.angle), pattern=args.pattern, feed=feed,
                     period=period, clearance=clearance(args), tol=tol,
                     progress=_progress(args), **spacing)
    t_cut = time.monotonic() - t0
    if not program.cuts:
        raise InputError(f"{args.step}: no pass cuts faces {' '.join(map(str, args.faces))}"
                         f" with a {radius:g} mm ball ({skipped_line(program) or 'nothing'})")
    title = f"finish R {radius:g} of {Path(args.step).name}"
    return gate_and_write(args, program, part, outputs, "finish", title, JOIN,
                          lambda p: _summary(p, args.step, time.monotonic() - t0, t_cut))


def _progress(args):
    """A progress(done, total, what) callback: a stderr line at most every second, and
    the last plane, or None with --quiet."""
    if args.quiet:
        return None
    last = [time.monotonic()]

    def report(done: int, total: int, what: str) -> None:
        now = time.monotonic()
        if now - last[0] >= PROGRESS_EVERY_S or done == total:
            last[0] = now
            say_error(f"cadcnc: finish: plane {done}/{total} ({what})")

    return report


def _summary(program, step: str, seconds: float, t_cut: float) -> str:
    job = program.job
    op = job.operation
    links = program.links[1:-1]  # between cuts: not the first approach nor the last retract
    down = sum(1 for s in links if len(s.points) == 2 and not s.rapid.any())
    t = program.totals()
    spacing = (f"stepover {op.stepover:g} mm" if op.stepover is not None
               else f"scallop {op.scallop:g} mm")
    return "\n".join([
        f"{Path(step).name}: finish faces {' '.join(map(str, op.faces))}, ball R "
        f"{job.tool.radius:g} mm + allowance {job.tool.allowance:g} mm, {spacing}, angle "
        f"{op.angle:g} deg, {op.pattern}, feed {job.feed:g} mm/min, period "
        f"{job.period * 1000:g} ms (step {job.step:.3g} mm)",
        f"  passes     {len(program.cuts)} cuts; {down} links between them stay down, "
        f"{len(links) - down} retract; skipped {len(program.skipped)}"
        + (f" ({skipped_line(program)})" if program.skipped else ""),
        *[f"  {n}" for n in program.notes],
        f"  lengths    cut {t['cut_length_mm']:.1f} mm, links {t['link_length_mm']:.1f} mm; "
        f"time at feed {t['time_at_feed_s']:.1f} s",
        f"  status     {'complete' if program.complete else 'partial'}; computed in "
        f"{t_cut:.1f} s, gated and written in {seconds - t_cut:.1f} s",
    ])
