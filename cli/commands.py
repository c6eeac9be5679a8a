"""The subcommands: build the job from the options, call the library, print, write.

Each function takes the argparse namespace and returns the exit code; library errors
propagate to :func:`cadcnc.cli.app.main`, which prints them on one line.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import cadcnc
from cadcnc import apt
from cadcnc.errors import InputError
from cadcnc.geometry.report import concave_edges, faces_report
from cadcnc.io.output_set import OutputSet, check_destination
from cadcnc.io.gcode import written_moves
from cadcnc.io.outputs import SUFFIXES, render
from cadcnc.io.summary import summary
from cadcnc.verification import gouge_gate

from . import demo as demo_command, program_commands
from .feedback import progress, say_error, stage_progress
from .options import clearance, gcode_options, tolerances

GOUGE_REFUSED = 5  # exit code: the whole-part check found a gouge deeper than the limit
PARTIAL = 6  # exit code: the path stopped before its intended end


# -- faces -----------------------------------------------------------------------------------
def faces(args) -> int:
    part = cadcnc.load_step(args.step, flip_material=args.flip_material)
    data = faces_report(part)
    for line in part.warnings:
        say_error(f"cadcnc: faces: OCCT's STEP reader: {line}")
    if args.json:
        print(json.dumps(data, indent=1))
        return 0
    print(f"{args.step}: {len(part)} faces; material side: {data['material']['rule']}")
    if data["material"].get("sewing"):
        sewn = data["material"]["sewing"]
        print(f"sewn at {sewn['tolerance_mm']:g} mm: largest edge tolerance "
              f"{sewn['max_edge_tolerance_mm']:.3g} mm, {sewn['free_edges']} free edges")
    print(f"{'face':>4}  {'kind':<10} {'area mm^2':>11}  neighbours: face class "
          "material-angle deg")
    for f in data["faces"]:
        nb = ", ".join(f"{n['face']} {n['class']} {_angles(n['angle_deg'])}"
                       for n in f["neighbours"])
        print(f"{f['number']:>4}  {f['kind']:<10} {f['area_mm2']:>11.2f}  {nb}")
    if not data["concave_pairs"]:
        print("\nno concave pairs: no two faces meet in an inner corner a ball can follow")
        return 0
    print("\nconcave pairs, the candidates for `cadcnc path --faces I J` "
          "(a ball can sit in these corners):")
    for i, j, k, e in concave_edges(data):
        print(f"  {i:>3} {j:<3}  edge {k}: {'closed' if e['closed'] else 'open'}, "
              f"{e['length_mm']:.3f} mm, material angle {_angles(e['angle_deg'])} deg")
    return 0


def _angles(rng) -> str:
    lo, hi = rng
    return f"{lo:.1f}" if abs(hi - lo) < 0.05 else f"{lo:.1f}..{hi:.1f}"


# -- path (programs: cli/program_commands.py) ------------------------------------------
def judge(args, tp, part, what: str, gopts: dict | None = None) -> tuple[bool, int]:
    """(write it?, exit code) for a computed path: the exit code is 0 only for a complete
    path that passed the whole-part gouge gate. With G-code options ``gopts`` (a program is
    written), the gate checks the moves as written: points dropped, rounded, tool-tip
    offset taken back, approach and retract.

    A partial path exits 6 and is written only with ``--allow-partial``; a gouging one
    exits 5 and is written only with ``--allow-gouge``. Messages go to stderr.
    """
    write, code = True, 0
    if not tp.complete:
        write, code = args.allow_partial, PARTIAL
        say_error(f"cadcnc: {what}: partial: {tp.partial_reason}"
                  + ("" if write else "; nothing written (--allow-partial writes it)"))
    if write:
        moves = None if gopts is None else written_moves(tp, **gopts)
        gate = gouge_gate(tp, part, tp.job.tolerances, moves=moves,
                          progress=stage_progress(args, f"{what}: gouge check", after_s=1.0))
        if not gate.ok:
            write, code = args.allow_gouge, GOUGE_REFUSED
            if write:
                what_cut = gate.message.replace("refused: ", "").replace("; nothing written", "")
                say_error(f"cadcnc: {what}: {what_cut}; written anyway (--allow-gouge)")
            else:
                say_error(f"cadcnc: {what}: {gate.message}. {_hint(tp, gate, gopts)}"
                          "--allow-gouge writes it")
    return write, code


def _hint(tp, gate, gopts) -> str:
    """What may help: fewer dropped points when only the moves between the written points
    cut (the centres are clear); a smaller ball for a side cut, not for a centre on or in
    the part."""
    if gopts and gopts.get("tolerance") and not any(
            h.depth_mm > gate.limit_mm for h in gate.hits):
        return "A smaller --tolerance (fewer points dropped) may pass; "
    shallow = math.isfinite(gate.depth_mm) and gate.depth_mm < tp.job.tool.offset
    return "A smaller --radius may fit; " if shallow and not gate.in_material else ""


# -- run -------------------------------------------------------------------------------------
def run(args) -> int:
    requested = args.output or []
    if args.stream and requested:
        raise InputError("--stream prints increments instead of writing files: give "
                         "either --stream or -o")
    for out in requested:
        check_destination(out, SUFFIXES, inputs=[args.program])
    source = args.program
    entries, title = apt.read_program(source, tolerances(args), clearance(args))
    names = _output_names(requested, entries)
    outputs = OutputSet([n for group in names.values() for n in group], SUFFIXES,
                        inputs=[source, *{e.job.source for e in entries}])
    checked = apt.check(entries, source)
    if args.stream:
        return _stream(args, checked, source)
    paths, status = [], 0
    ngc = [out for out in names if Path(out).suffix.lower() == ".ngc"]
    gopts = (gcode_options(args, checked[0][0].job.clearance, [p for _, p in checked])
             if ngc else None)
    for entry, part in checked:
        tp = apt.run_job(entry, part, progress(args, f"PATH {entry.name}"), source)
        paths.append(tp)
        if not args.quiet:
            print(f"PATH {entry.name} (line {entry.line}): " + summary(tp, entry.job.source))
        if not requested:
            status = status or (0 if tp.complete else PARTIAL)
            continue
        write, code = judge(args, tp, part, f"{source}:{entry.line}: PATH {entry.name}",
                            gopts)
        if not write:
            return code
        status = status or code
    contents = {}
    for out, group in names.items():
        if out in ngc:
            contents[out] = render(paths, out, title=title or Path(source).name, **gopts)
        else:
            contents.update({name: render([tp], name) for name, tp in zip(group, paths)})
    outputs.write(contents)
    for out, group in names.items():
        if not args.quiet:
            print(f"wrote {', '.join(group)}")
    return status


def _output_names(requested, entries) -> dict[str, list[str]]:
    """{OUT: files}: .ngc holds every path; .json/.csv one file per path (OUT-NAME.json
    when the program has several)."""
    names = {}
    for out in requested:
        o = Path(out)
        if o.suffix.lower() == ".ngc" or len(entries) == 1:
            names[out] = [out]
        else:
            names[out] = [str(o.with_name(f"{o.stem}-{e.name}{o.suffix}")) for e in entries]
    return names


def _stream(args, checked, source: str) -> int:
    """Print each period's increment. Each path is computed and gated first (partial,
    gouge), then streamed from a fresh stepper: nothing unchecked reaches the axes."""
    write, status = sys.stdout.write, 0
    for entry, part in checked:
        tp = apt.run_job(entry, part, None, source)
        ok, code = judge(args, tp, part, f"{source}:{entry.line}: PATH {entry.name}")
        if not ok:
            return code
        status = status or code
        stepper, increments = apt.stream_job(entry, part, source)
        i, j = entry.job.operation.faces
        write(f"# PATH {entry.name}: faces {i} {j}, period {entry.job.period:g} s, start "
              f"{' '.join(f'{v:.9f}' for v in stepper.p)}\n")
        for dx, dy, dz in increments:
            write(f"{dx:.9f} {dy:.9f} {dz:.9f}\n")
        write(f"# stop after {stepper.cycles} cycles: {stepper.stop_reason}: "
              f"{stepper.stop_detail}\n")
    sys.stdout.flush()
    return status


COMMANDS = {"faces": faces, "path": program_commands.path, "run": run,
            "demo": demo_command.demo, "plot": program_commands.plot,
            "verify": program_commands.verify}
