"""The subcommands: build the job from the options, call the library, print, write.

Each function takes the argparse namespace and returns the exit code; library errors
propagate to :func:`cadcnc.cli.main.main`, which prints them on one line.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import cadcnc
from cadcnc import apt
from cadcnc.errors import InputError, OutputError
from cadcnc.geometry.report import concave_edges, faces_report
from cadcnc.io import check_output, read_json, write_picture, write_toolpaths
from cadcnc.io.summary import summary
from cadcnc.ops.pair_path import path_for_job
from cadcnc.verification import gouge_gate, verify as run_verify

from . import demo as demo_command
from .feedback import progress, say_error
from .options import clearance, gcode_options, job_from_args, tolerances, wants_gcode

GOUGE_REFUSED = 5  # exit code: the whole-part check found a gouge deeper than the limit


def refuse_gouge(tp, part, what: str) -> str:
    """'' when the whole-part gate passes, else the refusal line for stderr."""
    gate = gouge_gate(tp, part, tp.job.tolerances)
    if gate.ok:
        return ""
    hint = "A smaller --radius may fit; " if math.isfinite(gate.depth_mm) else ""
    return f"cadcnc: {what}: {gate.message}. {hint}--allow-gouge writes it anyway"


# -- faces -----------------------------------------------------------------------------------
def faces(args) -> int:
    part = cadcnc.load_step(args.step)
    data = faces_report(part)
    for line in part.warnings:
        say_error(f"cadcnc: faces: OCCT's STEP reader: {line}")
    if args.json:
        print(json.dumps(data, indent=1))
        return 0
    print(f"{args.step}: {len(part)} faces")
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


# -- path ------------------------------------------------------------------------------------
def path(args) -> int:
    for out in args.output:
        check_output(out)
    job = job_from_args(args, args.step)
    part = cadcnc.load_step(args.step)
    for n in job.operation.faces:  # face numbers checked before anything is computed
        part.face(n)
    gopts = gcode_options(args, job.clearance, [part]) if wants_gcode(args.output) else {}
    i, j = job.operation.faces
    tp = path_for_job(part, job, progress=progress(args, f"faces {i} {j}"))
    if not args.allow_gouge:
        refused = refuse_gouge(tp, part, "path")
        if refused:
            say_error(refused)
            return GOUGE_REFUSED
    title = f"faces {i} {j} of {Path(args.step).name}"
    for out in args.output:
        write_toolpaths([tp], out, title=title, **gopts)
    if not args.quiet:
        print(summary(tp, args.step))
        print(f"  wrote      {', '.join(args.output)}")
    return 0


# -- run -------------------------------------------------------------------------------------
def run(args) -> int:
    outputs = args.output or []
    if args.stream and outputs:
        raise InputError("--stream prints increments instead of writing files: give "
                         "either --stream or -o")
    for out in outputs:
        check_output(out)
    source = args.program
    entries, title = apt.read_program(source, tolerances(args), clearance(args))
    checked = apt.check(entries, source)
    if args.stream:
        return _stream(checked, source)
    paths = []
    for entry, part in checked:
        tp = apt.run_job(entry, part, progress(args, f"PATH {entry.name}"), source)
        paths.append(tp)
        if not args.quiet:
            print(f"PATH {entry.name} (line {entry.line}): " + summary(tp, entry.job.source))
        refused = "" if args.allow_gouge or not outputs else refuse_gouge(tp, part, "path")
        if refused:
            say_error(f"{source}:{entry.line}: PATH {entry.name}: " + refused)
            return GOUGE_REFUSED
    for out in outputs:
        written = _write_program(args, out, paths, checked, title or Path(source).name)
        if not args.quiet:
            print(f"wrote {', '.join(written)}")
    return 0


def _write_program(args, out, paths, checked, title: str) -> list[str]:
    """.ngc: one program for all paths; .json/.csv: one file per path (OUT-NAME.json)."""
    if Path(out).suffix.lower() == ".ngc":
        gopts = gcode_options(args, checked[0][0].job.clearance, [p for _, p in checked])
        write_toolpaths(paths, out, title=title, **gopts)
        return [out]
    if len(paths) == 1:
        write_toolpaths(paths, out)
        return [out]
    o = Path(out)
    written = [str(o.with_name(f"{o.stem}-{entry.name}{o.suffix}")) for entry, _ in checked]
    for tp, name in zip(paths, written):
        write_toolpaths([tp], name)
    return written


def _stream(checked, source: str) -> int:
    """Print each period's increment; a streamed path is gated before its first increment."""
    write = sys.stdout.write
    for entry, part in checked:
        stepper, increments = apt.stream_job(entry, part, source)
        i, j = entry.job.operation.faces
        write(f"# PATH {entry.name}: faces {i} {j}, period {entry.job.period:g} s, start "
              f"{' '.join(f'{v:.9f}' for v in stepper.p)}\n")
        for dx, dy, dz in increments:
            write(f"{dx:.9f} {dy:.9f} {dz:.9f}\n")
        write(f"# stop after {stepper.cycles} cycles: {stepper.stop_reason}: "
              f"{stepper.stop_detail}\n")
    sys.stdout.flush()
    return 0


# -- plot ------------------------------------------------------------------------------------
def load_saved(path_json: str, part_file: str | None):
    """(toolpath, part) of a saved path JSON; the part from ``part_file`` or the record."""
    tp = read_json(path_json)
    if part_file is None:
        part_file = tp.job.source
        if not part_file:
            raise InputError(f"{path_json}: records no part file; give --part PART.step")
        if not Path(part_file).is_absolute() and not Path(part_file).exists():
            near = Path(path_json).parent / part_file
            part_file = str(near) if near.exists() else part_file
    return tp, cadcnc.load_step(part_file)


def plot(args) -> int:
    if Path(args.output).suffix.lower() not in (".png", ".glb"):
        raise OutputError(f"{args.output}: unknown picture format "
                          f"{Path(args.output).suffix or '(no suffix)'!r}; use .png or .glb")
    tp, part = load_saved(args.path_json, args.part)
    for n in tp.faces:
        if n is not None:
            part.face(n)
    write_picture(tp, part, args.output)
    if not args.quiet:
        print(f"wrote {args.output}")
    return 0


# -- verify ----------------------------------------------------------------------------------
def verify(args) -> int:
    tol = tolerances(args)
    if args.input.lower().endswith(".json"):
        tp, part = load_saved(args.input, args.part)
    else:
        if args.part is not None:
            raise InputError("--part is for a saved PATH.json; a STEP input is the part")
        job = job_from_args(args, args.input)
        part = cadcnc.load_step(args.input)
        tp = path_for_job(part, job, progress=progress(args, "verify"))
    report = run_verify(tp, part, tol=tol, progress=_verify_progress(args))
    if args.json:
        print(json.dumps(report.to_dict(), indent=1))
    else:
        print(report.format_table(tol.gouge))
    if report.ok(tol.gouge):
        return 0
    if not math.isfinite(report.max_gouge_mm):
        say_error("cadcnc: verify: the gouge depth could not be measured")
        return GOUGE_REFUSED
    say_error(f"cadcnc: verify: gouge {report.max_gouge_mm:.4g} mm deep exceeds the "
              f"tolerance {tol.gouge:g} mm (see max over-cut and whole-part hits)")
    return GOUGE_REFUSED


def _verify_progress(args):
    if args.quiet:
        return None
    seen = set()

    def report(stage: str, done: int, total: int) -> None:
        if stage not in seen:  # one line per stage: the stages count differently
            seen.add(stage)
            say_error(f"cadcnc: verify: {stage} ...")

    return report


COMMANDS = {"faces": faces, "path": path, "run": run, "demo": demo_command.demo,
            "plot": plot, "verify": verify}
