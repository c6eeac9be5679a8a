"""``cadcnc simulate``: the stock cut by programs, compared with the part (docs/simulate.md).

Parses, calls :func:`cadcnc.simulation.simulator.simulate`, writes the outputs (all or none),
prints the summary. Exit 0 no gouge and no collision, 5 a gouge deeper than
``--gouge-tolerance`` or a rapid through stock (the report and pictures are written all the
same: they show where), 2 bad input or work over its limit, 4 an output that cannot be
written (checked first).
"""

from __future__ import annotations

from cadcnc.core.errors import InputError
from cadcnc.core.units import parse_length


def add_parser(add, gouge) -> None:
    """Register ``simulate`` with ``add(name, help, description)`` and the gouge option."""
    p = add("simulate", "simulate the stock cut by programs; material left per face, gouges",
            "Cut a stock (tri-dexel: rays along X, Y and Z holding exact intervals of "
            "material) by every move of every program in order, ball and shank, and compare "
            "it with the part at every ray's crossing of its surface: material left per face, "
            "gouges, rapids through stock. Outputs by suffix: .json (the report), .png (the "
            "part coloured by the material left), .glb (the same with the stock), .stl (the "
            "stock). Exit 5 on a gouge or a collision (outputs written all the same).")
    p.add_argument("step", metavar="PART.step", help="the part (STEP file, mm)")
    p.add_argument("programs", nargs="+", metavar="PROGRAM",
                   help="cadcnc program JSON (each with its setup's axis and ball), or 3-axis "
                        "G-code (.ngc, .nc, .gcode, .tap; read by LinuxCNC's rs274, needs "
                        "--radius); applied in the order given")
    p.add_argument("--stock", nargs="+", default=["box"], metavar="KIND",
                   help="box [MARGIN] (the part's box grown by MARGIN mm, default 1), "
                        "offset MM (the part offset by MM), or STOCK.step (a solid)")
    p.add_argument("--resolution", default="0.1", metavar="MM",
                   help="the rays' spacing, mm (default 0.1)")
    p.add_argument("--radius", metavar="R", help="ball radius of G-code programs, mm")
    p.add_argument("--tool-tip", action="store_true",
                   help="G-code programs the tool tip (ball centre Z - R), not the centre")
    p.add_argument("--shank", metavar="MM",
                   help="shank length above the ball centre, mm (default: up to the "
                        "clearance height)")
    p.add_argument("--threshold", metavar="MM",
                   help="material left counted in area_over_mm2 (default: the finish "
                        "scallop target, else 0.01)")
    p.add_argument("--jobs", dest="threads", type=int, default=None, metavar="N",
                   help="threads (default: every core)")
    p.add_argument("-o", "--output", action="append", required=True, metavar="OUT",
                   help=".json, .png, .glb or .stl; repeat for several")
    gouge(p, gate=False)


def _stock(words: list[str]):
    kind = words[0].lower()
    if kind == "box" and len(words) <= 2:
        return ("box", parse_length(words[1], "stock margin", allow_zero=True)) \
            if len(words) == 2 else "box"
    if kind == "offset" and len(words) == 2:
        return parse_length(words[1], "stock offset", allow_zero=True)
    if len(words) == 1 and words[0].lower().endswith((".step", ".stp")):
        return words[0]
    raise InputError(f"--stock {' '.join(words)}: give box [MARGIN], offset MM or "
                     "STOCK.step")


def simulate_command(args) -> int:
    import cadcnc  # ~1.5 s (OCCT): not for --help
    from cadcnc.simulation.report_files import check_outputs, write_outputs
    from cadcnc.simulation.simulator import simulate

    from .options import tolerances

    outputs = check_outputs(args.output, inputs=[args.step, *args.programs])
    stock = _stock(args.stock)
    if args.threads is not None and args.threads < 1:
        raise InputError(f"--jobs must be >= 1, got {args.threads}")
    part = cadcnc.load_step(args.step, tolerances(args))
    opt = lambda v, name: None if v is None else parse_length(v, name)  # noqa: E731
    report = simulate(part, args.programs, stock=stock,
                      resolution=parse_length(args.resolution, "resolution"),
                      jobs=args.threads, radius=opt(args.radius, "radius"),
                      tool_tip=args.tool_tip, shank=opt(args.shank, "shank"),
                      threshold=opt(args.threshold, "threshold"))
    write_outputs(report, part, outputs, f"{args.step}: {', '.join(args.programs)}")
    if not args.quiet:
        print(report.summary())
        print("wrote " + ", ".join(str(d) for d in outputs.destinations))
    return report.exit_code
