"""``cadcnc simulate``'s options (the command: :func:`cadcnc.cli.simulate_command.simulate`;
the run: :func:`cadcnc.simulation.simulator.simulate`)."""

from __future__ import annotations


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
                   help="shank length above the ball centre, mm (default: a cadcnc "
                        "program's own tool's, 10 R unless its job set it; G-code: up to "
                        "its highest point)")
    p.add_argument("--threshold", metavar="MM",
                   help="material left counted in area_over_mm2 (default: the finish "
                        "scallop target, else 0.01)")
    p.add_argument("--jobs", dest="threads", type=int, default=None, metavar="N",
                   help="threads (default: every core)")
    p.add_argument("-o", "--output", action="append", required=True, metavar="OUT",
                   help=".json, .png, .glb or .stl; repeat for several")
    gouge(p, gate=False)
