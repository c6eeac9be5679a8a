"""``cadcnc simulate``: the stock cut by programs, compared with the part (docs/simulate.md;
the options: :mod:`cadcnc.cli.simulate_options`).

Reads the options, calls :func:`cadcnc.simulation.simulator.simulate`, writes the outputs
(all or none), prints the summary. Exit 0 no gouge and no collision, 5 a gouge deeper than
``--gouge-tolerance`` or a rapid through stock (the report and pictures are written all the
same: they show where), 2 bad input or work over its limit, 4 an output that cannot be
written (checked first).
"""

from __future__ import annotations

from pathlib import Path

from cadcnc.core.errors import InputError
from cadcnc.core.units import parse_length
from cadcnc.geometry.part import load_step
from cadcnc.simulation.report_files import check_outputs, write_outputs
from cadcnc.simulation.simulator import simulate as run_simulation
from cadcnc.simulation.stock_mesh import MESH_SUFFIXES, mesh_note

from .options import tolerances


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


def _length(value, name: str) -> float | None:
    return None if value is None else parse_length(value, name)


def simulate(args) -> int:
    outputs = check_outputs(args.output, inputs=[args.step, *args.programs])
    stock = _stock(args.stock)
    if args.threads is not None and args.threads < 1:
        raise InputError(f"--jobs must be >= 1, got {args.threads}")
    part = load_step(args.step, tolerances(args))
    report = run_simulation(part, args.programs, stock=stock,
                      resolution=parse_length(args.resolution, "resolution"),
                      jobs=args.threads, radius=_length(args.radius, "radius"),
                      tool_tip=args.tool_tip, shank=_length(args.shank, "shank"),
                      threshold=_length(args.threshold, "threshold"))
    write_outputs(report, part, outputs, f"{args.step}: {', '.join(args.programs)}")
    if not args.quiet:
        print(report.summary())
        note = mesh_note(report.stock)
        if note and any(Path(d).suffix.lower() in MESH_SUFFIXES for d in outputs.destinations):
            print("  " + note)
        print("wrote " + ", ".join(str(d) for d in outputs.destinations))
    return report.exit_code
