"""``cadcnc pencil``'s options: every inner corner of a part in one program, gated, written
all at once (registered by :mod:`cadcnc.cli.app` with :func:`add_parser`; the command is
:func:`cadcnc.cli.operation_commands.pencil`).

Exit codes like ``path``: 0 for a complete program that passed the gouge gate (every cut,
then every move of the whole program, links included, as written), 5 a gouge, 6 partial
(a cut stopped short), with ``--allow-gouge`` / ``--allow-partial`` to write anyway.
"""

from __future__ import annotations

from .operation_options import add_operation_options


def add_parser(add, job_flip, gouge, gcode) -> None:
    """Register ``pencil`` with ``add(name, help, description)`` and the shared option
    groups of :mod:`cadcnc.cli.app` (flip-material, gouge gate, G-code)."""
    p = add("pencil", "clean every inner corner of a part in one program",
            "Find every concave corner of the part a ball of radius R' = R + C can clean "
            "(shared concave edges, blends smaller than the ball), cut every feasible "
            "stretch, chain and link them, gate the whole program and write it: .json "
            "(program), .ngc, .csv (a row per cycle of every cut), .png or .glb (picture). "
            "Exit codes: docs/reliability.md.")
    p.add_argument("step", metavar="PART.step", help="the part (STEP file, mm)")
    p.add_argument("--radius", required=True, metavar="R", help="ball radius, mm")
    add_operation_options(p, "stock allowance left on every face")
    p.add_argument("--faces", nargs="+", type=int, metavar="N",
                   help="only corners whose two faces are among these (default: all)")
    p.add_argument("--side", choices=("climb", "conventional"), default="climb",
                   help="direction along the corners (default climb: material on the "
                        "right of the travel, clockwise spindle)")
    p.add_argument("--setups", metavar="AXES",
                   help="the fewest setups: auto (among +Z -Z +X -X +Y -Y) or a list such "
                        "as +Z,-X; one program per setup, its axis added to each output name "
                        "(docs/setups.md)")
    p.add_argument("--setup-overlap", default="0", metavar="MM",
                   help="with --setups: lap a later setup this far into what an earlier "
                        "one cut, mm (default 0: nothing cut twice)")
    job_flip(p)
    gouge(p)
    gcode(p)
