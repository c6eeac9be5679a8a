"""``cadcnc finish``'s options: raster finishing of selected faces in one program, gated,
written (registered by :mod:`cadcnc.cli.app` with :func:`add_parser`; the command is
:func:`cadcnc.cli.operation_commands.finish`).

Exit codes as ``pencil``: 0 for a complete program that passed the gouge gate (every cut,
then every move of the whole program, links included, as written), 5 a gouge, 6 partial
(a cut stopped short), 2 bad input, with ``--allow-gouge`` / ``--allow-partial`` to write
anyway.
"""

from __future__ import annotations

from .operation_options import add_operation_options


def add_parser(add, job_flip, gouge, gcode) -> None:
    """Register ``finish`` with ``add(name, help, description)`` and the shared option
    groups of :mod:`cadcnc.cli.app` (flip-material, gouge gate, G-code)."""
    p = add("finish", "raster-finish selected faces (guide-plane passes) in one program",
            "Cut raster passes over the selected faces: the ball (R' = R + C) touches the "
            "faces while its centre stays on vertical guide planes at --angle to X, spaced "
            "by --stepover or so that the scallop stays within --scallop; zigzag or one-way, "
            "linked; gate the whole program and write it: .json (program), .ngc, .csv (a "
            "row per cycle of every cut), .png or .glb (picture). Exit codes: "
            "docs/reliability.md.")
    p.add_argument("step", metavar="PART.step", help="the part (STEP file, mm)")
    p.add_argument("--faces", nargs="+", type=int, required=True, metavar="N",
                   help="the faces to finish, numbered as `cadcnc faces`")
    p.add_argument("--radius", required=True, metavar="R", help="ball radius, mm")
    spacing = p.add_mutually_exclusive_group()
    spacing.add_argument("--stepover", metavar="S", help="distance between the passes' "
                         "guide planes, mm")
    spacing.add_argument("--scallop", metavar="H", help="largest scallop height, mm: the "
                         "planes' spacing follows the faces' curvature and slope")
    p.add_argument("--angle", metavar="A",
                   help="direction of the passes, degrees from +X (default 0)")
    p.add_argument("--pattern", choices=("zigzag", "oneway"),
                   help="zigzag (default: every other pass reversed, staying down where the "
                        "move is verified clear) or oneway (every pass the same way, "
                        "retracting between)")
    p.add_argument("--strategy", choices=("raster", "waterline", "steep-shallow"),
                   default="raster", help="raster (default: vertical guide planes), "
                   "waterline (horizontal levels, top to bottom) or steep-shallow "
                   "(waterline where the slope exceeds --threshold, raster elsewhere; "
                   "docs/finish.md)")
    p.add_argument("--stepdown", metavar="D", help="waterline: distance between levels, mm "
                   "(or --scallop: the levels' spacing follows the walls' slope)")
    p.add_argument("--threshold", metavar="A", help="steep-shallow: slope "
                   "in degrees from horizontal above which waterline cuts (default 45)")
    p.add_argument("--side", choices=("climb", "conventional"),
                   help="waterline loops: climb (default) or conventional")
    p.add_argument("--overlap", metavar="MM", help="steep-shallow: the "
                   "regions overlap this much at their boundary, mm (default 0)")
    add_operation_options(p, "stock allowance left on the faces")
    job_flip(p)
    gouge(p)
    gcode(p)
