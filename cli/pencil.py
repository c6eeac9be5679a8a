"""``cadcnc pencil``: every inner corner of a part in one program, gated, written all at once.

Options are defined here (registered by :mod:`cadcnc.cli.app` with :func:`add_parser`).
Exit codes like ``path``: 0 for a complete program that passed the gouge gate (every cut,
then every move of the whole program, links included, as written), 5 a gouge, 6 partial
(a cut stopped short), with ``--allow-gouge`` / ``--allow-partial`` to write anyway.
"""

from __future__ import annotations

import time
from pathlib import Path

from cadcnc.errors import InputError  # light: OCCT is imported in pencil_command
from cadcnc.units import parse_duration, parse_feed, parse_length

from .feedback import say_error
from .operation import SUFFIXES, add_operation_options, gate_and_write, skipped_line


def add_parser(add, job_flip, gouge, gcode) -> None:
    """Register ``pencil`` with ``add(name, help, description)`` and the shared option
    groups of :mod:`cadcnc.cli.app` (flip-material, gouge gate, G-code)."""
    p = add("pencil", "clean every inner corner of a part in one program",
            "Find every concave corner of the part a ball of radius R' = R + C can clean "
            "(shared concave edges, blends smaller than the ball), cut every feasible "
            "stretch, chain and link them, gate the whole program and write it: .json "
            "(program), .ngc, .csv (a row per cut point), .png or .glb (picture).")
    p.add_argument("step", metavar="PART.step", help="the part (STEP file, mm)")
    p.add_argument("--radius", required=True, metavar="R", help="ball radius, mm")
    add_operation_options(p, "stock allowance left on every face")
    p.add_argument("--faces", nargs="+", type=int, metavar="N",
                   help="only corners whose two faces are among these (default: all)")
    p.add_argument("--side", choices=("climb", "conventional"), default="climb",
                   help="direction along the corners (default climb: material on the "
                        "right of the travel, clockwise spindle)")
    job_flip(p)
    gouge(p)
    gcode(p)


def pencil_command(args) -> int:
    import cadcnc
    from cadcnc.io.output_set import OutputSet
    from cadcnc.ops.pencil.pencil import CHAIN_GAP, pencil

    from .options import clearance, tolerances

    outputs = OutputSet(args.output, SUFFIXES, inputs=[args.step])
    radius = parse_length(args.radius, "radius", allow_zero=False)
    allowance = parse_length(args.allowance, "allowance")
    feed, period = parse_feed(args.feed), parse_duration(args.period)
    tol = tolerances(args)
    t0 = time.monotonic()
    part = cadcnc.load_step(args.step, flip_material=args.flip_material)
    times = {"load": time.monotonic() - t0}
    for n in args.faces or ():
        part.face(n)  # face numbers checked before anything is computed
    report = None if args.quiet else (
        lambda done, total, what: say_error(f"cadcnc: pencil: corner {done}/{total} ({what})"))
    program = pencil(part, radius=radius, allowance=allowance, feed=feed, period=period,
                     faces=None if args.faces is None else set(args.faces),
                     clearance=clearance(args), side=args.side, tol=tol, progress=report,
                     times=times)
    t_cut = time.monotonic() - t0
    if not program.cuts:
        raise InputError(f"{args.step}: no corner to cut with a {radius:g} mm ball "
                         f"({skipped_line(program) or 'no concave corner found'})")
    title = f"pencil R {radius:g} of {Path(args.step).name}"

    def summary(p) -> str:   # called once the program is gated: verification time known
        times["verification"] = time.monotonic() - t0 - t_cut
        return _summary(p, args.step, time.monotonic() - t0, t_cut, times)

    return gate_and_write(args, program, part, outputs, "pencil", title, CHAIN_GAP, summary)


def _summary(program, step: str, seconds: float, t_cut: float, times: dict) -> str:
    job = program.job
    segs = program.segments
    chains = sum(1 for a, b in zip(segs, segs[1:])  # a lift (rapid) before a cut
                 if a.kind == "link" and a.rapid.any() and b.kind == "cut")
    t = program.totals()
    return "\n".join([
        f"{Path(step).name}: pencil, ball R {job.tool.radius:g} mm + allowance "
        f"{job.tool.allowance:g} mm, feed {job.feed:g} mm/min, period "
        f"{job.period * 1000:g} ms (step {job.feed / 60 * job.period:.3g} mm)",
        f"  corners    {len(program.cuts)} cuts in {chains} chains; skipped "
        f"{len(program.skipped)}" + (f" ({skipped_line(program)})" if program.skipped else ""),
        f"  lengths    cut {t['cut_length_mm']:.1f} mm, links {t['link_length_mm']:.1f} mm; "
        f"time at feed {t['time_at_feed_s']:.1f} s",
        f"  status     {'complete' if program.complete else 'partial'}; computed in "
        f"{t_cut:.1f} s, gated and written in {seconds - t_cut:.1f} s",
        "  times      " + ", ".join(f"{k} {v:.1f} s" for k, v in times.items()),
    ])
