"""The subcommands: parse the user's numbers, call the library, print, write.

Each function takes the argparse namespace and returns the exit code; library errors
propagate to :func:`cadcnc.cli.main.main`, which prints them on one line.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

VERIFY_FAILED = 5  # exit code of a failed `verify` gate (over-cut above the tolerance)
DEMO = dict(fixture="bspline_boss.step", faces=(4, 5), radius=3.0, feed=1500.0, period=0.004)


def _err(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def _progress(args, label: str):
    """A progress(cycles, mm) callback printing to stderr, or None with --quiet."""
    if args.quiet:
        return None

    def report(cycles: int, mm: float) -> None:
        _err(f"cadcnc: {label}: {cycles} cycles, {mm:.1f} mm")

    return report


def _job_kwargs(args) -> dict:
    """radius, allowance, feed, period, start, end, edge from the command line (mm, s)."""
    from cadcnc.errors import InputError
    from cadcnc.units import parse_duration, parse_feed, parse_length, parse_point

    missing = [f"--{n}" for n in ("faces", "radius", "feed", "period")
               if getattr(args, n) is None]
    if missing:
        raise InputError(f"computing a path needs {', '.join(missing)}")
    if args.edge < 1:
        raise InputError(f"--edge numbers the shared concave edges from 1, got {args.edge}")
    return dict(
        radius=parse_length(args.radius, "radius"),
        allowance=parse_length(args.allowance, "allowance"),
        feed=parse_feed(args.feed), period=parse_duration(args.period),
        start=None if args.start is None else parse_point(args.start, "start"),
        end=None if args.end is None else parse_point(args.end, "end"),
        edge=args.edge - 1)


def _compute(args, part, kwargs):
    import cadcnc

    i, j = args.faces
    s1, s2 = part.face(i), part.face(j)  # face numbers checked before anything else
    return cadcnc.intersection_path(s1, s2, progress=_progress(args, f"faces {i} {j}"),
                                    **kwargs)


def part_top(part) -> float:
    """Highest Z of the part's bounding box, mm."""
    import cadquery as cq

    return cq.Shape.cast(part.shape).BoundingBox().zmax


def _gcode_options(args, part) -> dict:
    from cadcnc.io.gcode import SAFE_MARGIN
    from cadcnc.units import parse_length

    tol = None if args.tolerance is None else parse_length(args.tolerance, "tolerance", False)
    if args.safe_z is not None:
        from cadcnc.errors import InputError

        try:
            safe_z = float(args.safe_z)
        except ValueError:
            raise InputError(f"--safe-z: expected a height in mm, got {args.safe_z!r}") from None
    else:
        safe_z = part_top(part) + SAFE_MARGIN if part is not None else None
    return dict(tolerance=tol, tool_tip=args.tool_tip, safe_z=safe_z, spindle=args.spindle)


def summary(path, part_name: str = "") -> str:
    """The one-screen summary of a toolpath."""
    from cadcnc.units import format_duration

    p = path.inputs
    step = p["feed"] * p["period"] / 60.0
    i, j = path.faces
    lines = [
        f"faces {i} and {j}" + (f" of {part_name}" if part_name else ""),
        f"  ball R {p['radius']:g} mm, allowance {p['allowance']:g} mm, feed {p['feed']:g} "
        f"mm/min, period {format_duration(p['period'])} (step {step:.6g} mm)",
        f"  points     {len(path)}",
        f"  length     {path.length:.4f} mm",
        f"  time       {path.duration:.4f} s",
        f"  stop       {path.stop_reason}: {path.stop_detail}",
        f"  predicted  {path.worst_predicted_mm:.3g} mm worst steady-state error (eq. 16)",
        f"  start      {_xyz(path.points[0])}",
        f"  end        {_xyz(path.points[-1])}",
    ]
    return "\n".join(lines)


def _xyz(p) -> str:
    return "(" + ", ".join(f"{v:.4f}" for v in p) + ") mm"


# -- faces -----------------------------------------------------------------------------------
def faces(args) -> int:
    import cadcnc

    part = cadcnc.load_step(args.step)
    data = faces_report(part)
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
    pairs = data["concave_pairs"]
    if pairs:
        print("\nconcave pairs, the candidates for `cadcnc path --faces I J` "
              "(a ball can sit in these corners):")
        for pr in data["pairs"]:
            if pr["class"] != "concave":
                continue
            for k, e in enumerate(pr["edges"], 1):
                print(f"  {pr['faces'][0]:>3} {pr['faces'][1]:<3}  edge {k}: "
                      f"{'closed' if e['closed'] else 'open'}, {e['length_mm']:.3f} mm, "
                      f"material angle {_angles(e['angle_deg'])} deg")
    else:
        print("\nno concave pairs: no two faces meet in an inner corner a ball can follow")
    return 0


def _angles(rng) -> str:
    lo, hi = rng
    return f"{lo:.1f}" if abs(hi - lo) < 0.05 else f"{lo:.1f}..{hi:.1f}"


def faces_report(part) -> dict:
    """Faces, neighbours and pairs as plain data (the --json output)."""
    def edge(e):
        lo, hi = e.angle_range_deg
        return {"class": e.edge_class, "angle_deg": [round(lo, 4), round(hi, 4)],
                "length_mm": round(e.length, 6), "closed": bool(e.closed)}

    out = {"file": str(part.source), "n_faces": len(part), "faces": [], "pairs": []}
    for f in part.faces:
        nbs = []
        for m, edges in sorted(part.neighbours(f.number).items()):
            lo = min(e.angle_range_deg[0] for e in edges)
            hi = max(e.angle_range_deg[1] for e in edges)
            nbs.append({"face": m, "class": part.pair_class(f.number, m),
                        "angle_deg": [round(lo, 4), round(hi, 4)], "edges": len(edges)})
        out["faces"].append({"number": f.number, "kind": f.kind,
                             "area_mm2": round(f.area(), 6), "reversed": bool(f.reversed),
                             "neighbours": nbs})
    for (i, j), edges in part.adjacency.items():
        out["pairs"].append({"faces": [i, j], "class": part.pair_class(i, j),
                             "edges": [edge(e) for e in edges]})
    out["concave_pairs"] = [list(p) for p in part.concave_pairs()]
    return out


# -- path ------------------------------------------------------------------------------------
def path(args) -> int:
    import cadcnc
    from cadcnc.io import check_output, write_toolpaths

    for out in args.output:
        check_output(out)
    kwargs = _job_kwargs(args)
    part = cadcnc.load_step(args.step)
    gopts = _gcode_options(args, part) if any(
        Path(o).suffix.lower() == ".ngc" for o in args.output) else {}
    tp = _compute(args, part, kwargs)
    if not args.allow_gouge:
        refused = _gouge_gate(tp, part, float(args.gouge_tolerance))
        if refused:
            _err(refused)
            return VERIFY_FAILED
    for out in args.output:
        write_toolpaths([tp], out, title=f"faces {tp.faces[0]} {tp.faces[1]} of "
                                         f"{Path(args.step).name}", **gopts)
    if not args.quiet:
        print(summary(tp, args.step))
        print(f"  wrote      {', '.join(args.output)}")
    return 0


def _gouge_gate(tp, part, tolerance_mm: float) -> str:
    """'' if the ball at every point clears every face of the part within the tolerance;
    otherwise the refusal message (faces hit, depth, cycles). No path that gouges the
    part is written silently."""
    report = _verification(tp, part)
    if report is None or report.ok(tolerance_mm):
        return ""
    hits = [h for h in report.whole_part_hits if h["depth_mm"] > tolerance_mm]
    what = "; ".join(f"face {h['face']} by {h['depth_mm']:.4g} mm over {h['n_cycles']} "
                     f"cycles" for h in hits) or f"over-cut {report.max_overcut_mm:.4g} mm"
    return (f"cadcnc: path: refused: the ball cuts into the part ({what}) beyond "
            f"{tolerance_mm:g} mm; nothing written. A smaller --radius may fit; "
            "--allow-gouge writes it anyway")


# -- run -------------------------------------------------------------------------------------
def run(args) -> int:
    from cadcnc import apt
    from cadcnc.errors import InputError
    from cadcnc.io import check_output, write_toolpaths

    outputs = args.output or []
    if args.stream and outputs:
        raise InputError("--stream prints increments instead of writing files: give "
                         "either --stream or -o")
    for out in outputs:
        check_output(out)
    source = args.program
    job_list, title = apt.read_program(source)
    checked = apt.check(job_list, source)
    if args.stream:
        return _stream(checked, source)
    paths = []
    for job, part in checked:
        tp = apt.run_job(job, part, _progress(args, f"PATH {job.name}"), source)
        paths.append(tp)
        if not args.quiet:
            print(f"PATH {job.name} (line {job.line}): " + summary(tp, job.part_file))
        refused = "" if args.allow_gouge or not outputs else _gouge_gate(
            tp, part, float(args.gouge_tolerance))
        if refused:
            _err(f"{source}:{job.line}: PATH {job.name}: " + refused)
            return VERIFY_FAILED
    for out in outputs:
        if Path(out).suffix.lower() == ".ngc":
            gopts = _gcode_options(args, checked[0][1])
            if args.safe_z is None:
                gopts["safe_z"] = max(part_top(p) for _, p in checked) + 10.0
            write_toolpaths(paths, out, title=title or Path(source).name, **gopts)
            written = [out]
        elif len(paths) == 1:
            write_toolpaths(paths, out)
            written = [out]
        else:
            o = Path(out)
            written = [str(o.with_name(f"{o.stem}-{job.name}{o.suffix}")) for job, _ in checked]
            for tp, name in zip(paths, written):
                write_toolpaths([tp], name)
        if not args.quiet:
            print(f"wrote {', '.join(written)}")
    return 0


def _stream(checked, source: str) -> int:
    from cadcnc import apt

    write = sys.stdout.write
    for job, part in checked:
        stepper, increments = apt.stream_job(job, part, source)
        write(f"# PATH {job.name}: faces {job.faces[0]} {job.faces[1]}, period "
              f"{job.period:g} s, start {' '.join(f'{v:.9f}' for v in stepper.p)}\n")
        for dx, dy, dz in increments:
            write(f"{dx:.9f} {dy:.9f} {dz:.9f}\n")
        write(f"# stop after {stepper.cycles} cycles: {stepper.stop_reason}: "
              f"{stepper.stop_detail}\n")
    sys.stdout.flush()
    return 0


# -- demo ------------------------------------------------------------------------------------
def demo_step() -> Path:
    """The bundled demo part: package data if shipped, else the source tree's fixtures."""
    import cadcnc
    from cadcnc.errors import StepFileError

    pkg = Path(cadcnc.__file__).resolve().parent
    for candidate in (pkg / "data" / DEMO["fixture"], pkg.parent / "fixtures" / DEMO["fixture"]):
        if candidate.is_file():
            return candidate
    raise StepFileError(f"the demo part {DEMO['fixture']} is not installed (looked in "
                        f"{pkg / 'data'} and {pkg.parent / 'fixtures'})")


def demo(args) -> int:
    import cadcnc
    from cadcnc.errors import OutputError
    from cadcnc.io.plot import write_picture
    from cadcnc.io import write_text, write_toolpaths

    step = demo_step()
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise OutputError(f"{out}: cannot create the demo folder ({e.strerror})") from e
    say = (lambda *a: None) if args.quiet else print
    i, j = DEMO["faces"]
    say(f"cadcnc demo: faces {i} (B-spline top) and {j} (cylindrical boss) of {step}")
    part = cadcnc.load_step(step)
    kwargs = dict(radius=DEMO["radius"], feed=DEMO["feed"], period=DEMO["period"])
    tp = cadcnc.intersection_path(part.face(i), part.face(j),
                                  progress=_progress(args, "demo"), **kwargs)
    say(summary(tp, step.name))
    files = {"path.json": None, "path.csv": None, "path.ngc": None}
    for name in files:
        write_toolpaths([tp], out / name, title=f"demo: faces {i} {j} of {step.name}",
                        safe_z=part_top(part) + 10.0)
    write_text(out / "demo.apt", _demo_program(step))
    report = _verification(tp, part)
    if report is not None:
        write_text(out / "verification.txt", report.format_table() + "\n")
        write_text(out / "verification.json",
                   json.dumps(report.to_dict(), indent=1, default=_jsonable) + "\n")
        d = report.to_dict()
        say(f"  verified   max over-cut {_fmt(d.get('max_overcut_mm'))} mm, max under-cut "
            f"{_fmt(d.get('max_undercut_mm'))} mm, Hausdorff to OCCT "
            f"{_fmt(d.get('hausdorff_mm'))} mm")
    else:
        say("  verified   (skipped: cadcnc.verification is not available)")
    write_picture(tp, part, out / "path.png", title=f"demo: faces {i} and {j} of {step.name}")
    say(f"wrote {out}/: " + ", ".join(sorted(p.name for p in out.iterdir()
                                             if not p.name.startswith("."))))
    return 0


def _demo_program(step: Path) -> str:
    i, j = DEMO["faces"]
    return (f"$$ the demo job as an APT-like program: cadcnc run demo.apt -o demo.ngc\n"
            f"PARTNO/'cadcnc demo'\nPART = '{step}'\n"
            f"CUTTER/R={DEMO['radius']:g}, C=0\nFEED/{DEMO['feed']:g}\n"
            f"PERIOD/{DEMO['period'] * 1000:g}ms\nBOSS = P/[F{i}, F{j}, EDGE, EDGE]\nFINI\n")


def _fmt(v) -> str:
    return "n/a" if v is None else f"{v:.3g}"


def _jsonable(o):
    import numpy as np

    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


def _verification(tp, part):
    """The verification report, or None when cadcnc.verification is not installed."""
    try:
        from cadcnc.verification import verify as run_verify
    except ImportError:
        return None
    return run_verify(tp, part)


# -- plot ------------------------------------------------------------------------------------
def _load_saved(path_json: str, part_file: str | None):
    import cadcnc
    from cadcnc.errors import InputError
    from cadcnc.io import read_json

    tp = read_json(path_json)
    if part_file is None:
        part_file = tp.inputs.get("source")
        if not part_file:
            raise InputError(f"{path_json}: records no part file; give --part PART.step")
        if not Path(part_file).is_absolute() and not Path(part_file).exists():
            near = Path(path_json).parent / part_file
            part_file = str(near) if near.exists() else part_file
    return tp, cadcnc.load_step(part_file)


def plot(args) -> int:
    from cadcnc.io.plot import write_picture
    from cadcnc.errors import OutputError

    if Path(args.output).suffix.lower() not in (".png", ".glb"):
        raise OutputError(f"{args.output}: unknown picture format "
                          f"{Path(args.output).suffix or '(no suffix)'!r}; use .png or .glb")
    tp, part = _load_saved(args.path_json, args.part)
    for n in tp.faces:
        if n is not None:
            part.face(n)
    write_picture(tp, part, args.output)
    if not args.quiet:
        print(f"wrote {args.output}")
    return 0


# -- verify ----------------------------------------------------------------------------------
def verify(args) -> int:
    import math

    import cadcnc
    from cadcnc.errors import CadcncError, InputError
    from cadcnc.units import parse_length

    tolerance = parse_length(args.tolerance, "tolerance")
    try:
        from cadcnc.verification import verify as run_verify
    except ImportError:
        raise CadcncError("verification is not available: this installation has no "
                          "cadcnc.verification module") from None
    if args.input.lower().endswith(".json"):
        tp, part = _load_saved(args.input, args.part)
    else:
        if args.part is not None:
            raise InputError("--part is for a saved PATH.json; a STEP input is the part")
        kwargs = _job_kwargs(args)
        part = cadcnc.load_step(args.input)
        tp = _compute(args, part, kwargs)
    report = run_verify(tp, part, progress=_verify_progress(args))
    data = report.to_dict()
    if args.json:
        print(json.dumps(data, indent=1, default=_jsonable))
    else:
        import inspect

        takes_tol = "tolerance_mm" in inspect.signature(report.format_table).parameters
        print(report.format_table(tolerance_mm=tolerance) if takes_tol
              else report.format_table())
    gouge = getattr(report, "max_gouge_mm", None)
    if gouge is None:
        hits = [_hit_depth(h) for h in data.get("whole_part_hits") or []]
        gouge = max([data.get("max_overcut_mm", float("nan")), *hits])
    if not math.isfinite(gouge):
        _err("cadcnc: verify: the over-cut could not be measured")
        return VERIFY_FAILED
    if gouge > tolerance:
        _err(f"cadcnc: verify: gouge {gouge:.4g} mm deep exceeds the tolerance "
             f"{tolerance:g} mm (see max over-cut and whole-part hits)")
        return VERIFY_FAILED
    return 0


def _verify_progress(args):
    if args.quiet:
        return None

    seen = set()

    def report(stage: str, done: int, total: int) -> None:
        if stage not in seen:  # one line per stage: the stages count differently
            seen.add(stage)
            _err(f"cadcnc: verify: {stage} ...")

    return report


def _hit_depth(hit) -> float:
    """Depth (mm) of a whole-part hit record, whatever its exact layout."""
    if isinstance(hit, dict):
        for key in ("depth_mm", "max_depth_mm", "depth"):
            if isinstance(hit.get(key), (int, float)):
                return float(hit[key])
        return float("inf")  # a hit of unknown depth fails the gate
    return float(getattr(hit, "depth_mm", getattr(hit, "depth", float("inf"))))
