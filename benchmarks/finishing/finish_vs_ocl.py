"""Guide-surface finishing against OpenCAMLib's drop-cutter (issue 13, docs/finish.md).

The same faces, the same pass lines (cadcnc's planes: angle 0, stepover 1 mm), the same
point spacing (cadcnc's step f = F Ts = 0.1 mm; OCL's points 0.1 mm apart along each
line), ball R = 3 mm: cadcnc's ball centres against OCL's BatchDropCutter on OCCT
tessellations of the faces at ``--tol`` (1e-2 and 1e-3 mm), one OCL thread, in a
subprocess (benchmarks/finishing/ocl_worker.py). Every ball centre's true deviation from the exact
offset of the faces is measured with OCCT (benchmarks/finishing/finish_bench_tools.py): max, p50,
p99 of |distance - R'|, gouge side and leave side, and the worst chord midpoint, counted
where the ball lies wholly over a face (its nearest point inside the face, the ball grown
by 0.5 mm clear of the face's boundary). Time per point: OCL's with its tessellation
(BRepMesh, building the STLSurf, appending the points, the run); cadcnc's with its
planning (reading the part, planes, passes, links, uncut report) and without the gouge
gate, which is timed separately; where cadcnc's time goes is timed inside it.

    python -m benchmarks.finishing.finish_vs_ocl [--slab] [--fixtures [NAME ...]] [--tol 1e-2 1e-3]
        [--json OUT] [--png docs/img/finish_vs_ocl.png]

``--slab`` (default when neither is given): the held-out-like free-form slab of
benchmarks/finishing/freeform_slab.py, 80 x 60 mm, and its picture. ``--fixtures``: the
fixtures/finish_*.step named in fixtures/finish_fixtures.json (all, or the NAMEs), on
their selected faces. Needs ``pip install -e '.[bench]'`` (opencamlib).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import cadcnc
from benchmarks import ROOT
from benchmarks.finishing import freeform_slab
from benchmarks.finishing.finish_bench_tools import FaceDistances, run_ocl, tessellate
from cadcnc.geometry.boxes import optimal_box
from cadcnc.verification import gate_program

R, FEED, PERIOD = 3.0, 1500.0, 0.004
SPACING = FEED * PERIOD / 60.0    # 0.1 mm: cadcnc's step, OCL's point spacing
clock = time.perf_counter


@dataclass
class CadcncRun:
    polylines: list            # [(N_k, 3)] ball centres of every cut, in order
    offsets: list              # plane offset (mm, along the plane normal) of each cut
    seconds: float             # part, planning and cutting, gate excluded
    seconds_part: float        # of which reading the shape into a Part
    seconds_gate: float | None  # the verification gate alone (None: not run)
    points: int
    gate_ok: bool | None = None
    skipped: list | None = None  # what the program lists as not cut
    parts: dict | None = None    # {what: (seconds, calls)} inside cadcnc.finish


def plane_frame(angle: float) -> tuple[np.ndarray, np.ndarray]:
    """(direction, normal) of guide planes at ``angle`` degrees to +X (FINISH_INTERFACE)."""
    a = np.radians(angle)
    return np.array([np.cos(a), np.sin(a), 0.0]), np.array([-np.sin(a), np.cos(a), 0.0])


class Stopwatch:
    """Seconds spent in named functions of cadcnc's finishing (wrapped in place while a
    run is timed; a wrapper costs about 0.3 µs a call): where cadcnc's time goes."""

    WATCHED = [("cadcnc.ops.finish.raster", "plan_for_job", "planning (planes, face sampling)"),
               ("cadcnc.ops.finish.raster", "measured_rows", "uncut report (cut points' tree)"),
               ("cadcnc.ops.finish.raster", "uncut_from_rows", "uncut report (areas, reasons)"),
               ("cadcnc.ops.finish.uncut", "_reasons",
                "of which reasons (guard on samples)"),
               ("cadcnc.ops.finish.raster", "entered_items", "entries"),
               ("cadcnc.ops.finish.raster", "linked", "links (zigzag links verified)"),
               ("cadcnc.guard.stay_down", "witness",
                "of which stay-down witnesses (refutations)"),
               ("cadcnc.guard.moves", "MoveClearance.distance",
                "of which stay-down checks (OCCT)"),
               ("cadcnc.ops.finish.raster", "pass_cuts", "passes (stepping, guard, exact step)"),
               ("cadcnc.ops.finish.passes", "_Pass.exact", "points onto the exact offset"),
               ("cadcnc.guard.clearance", "ClearanceGuard.margin",
                "clearance guard (every face, ball and shank)"),
               ("cadcnc.guard.clearance", "ClearanceGuard._exact",
                "of which per-face checks (proofs, else OCCT)"),
               ("cadcnc.guard.clearance", "ClearanceGuard._segment_distance",
                "of which exact segment distances (closed form, else OCCT)"),
               ("cadcnc.guard.guard", "OperationGuard.budget",
                "guard budgets (steps then left to the kernel)")]

    def __init__(self):
        self.seconds: dict[str, float] = {}
        self.calls: dict[str, int] = {}
        self._undo = []

    def __enter__(self):
        import importlib
        for module, name, label in self.WATCHED:
            owner = importlib.import_module(module)
            *path, attr = name.split(".")
            for part in path:
                owner = getattr(owner, part)
            self._wrap(owner, attr, label)
        return self

    def _wrap(self, owner, attr: str, label: str) -> None:
        original = getattr(owner, attr)
        self.seconds[label], self.calls[label] = 0.0, 0

        def timed(*args, **kwargs):
            t0 = clock()
            try:
                return original(*args, **kwargs)
            finally:
                self.seconds[label] += clock() - t0
                self.calls[label] += 1

        setattr(owner, attr, timed)
        self._undo.append((owner, attr, original))

    def __exit__(self, *exc):
        for owner, attr, original in reversed(self._undo):
            setattr(owner, attr, original)


def cadcnc_finish(shape, faces: list[int], *, radius: float, stepover: float,
                  angle: float, source: str) -> CadcncRun:
    """cadcnc's finishing program of ``faces`` of ``shape`` (``cadcnc.finish``: planes,
    passes, links, uncut report), timed from reading the shape into a Part; then the
    whole-program gouge gate (``gate_program``), timed apart."""
    t0 = clock()
    part = cadcnc.Part(shape, source=source)
    t_part = clock() - t0
    with Stopwatch() as watch:
        program = cadcnc.finish(part, faces, radius=radius, stepover=stepover, angle=angle,
                                feed=FEED, period=PERIOD)
    seconds = clock() - t0
    t1 = clock()
    gate = gate_program(program, part)
    t_gate = clock() - t1
    if not gate.ok:
        print(f"{source}: the gate refuses the program: {gate.message}", file=sys.stderr)
    _, normal = plane_frame(angle)
    polylines = [c.points for c in program.cuts]
    offsets = [float(np.round(np.median(pl @ normal), 9)) for pl in polylines]
    return CadcncRun(polylines, offsets, seconds, t_part, t_gate,
                     int(sum(len(p) for p in polylines)), bool(gate.ok),
                     [f"{s.reason}: {s.detail}" for s in program.skipped],
                     {k: (v, watch.calls[k]) for k, v in watch.seconds.items()})


def ocl_points(faces_topods, offsets: list, angle: float) -> tuple[np.ndarray, list]:
    """((N, 2) x, y of OCL's cutter locations, [(start, stop)] rows of each line): every
    plane offset's line across the faces' box, SPACING apart (the box's ends included)."""
    boxes = [optimal_box(f, use_triangulation=False) for f in faces_topods]
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    direction, normal = plane_frame(angle)
    corners = np.array([[x, y, 0.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])])
    s = np.arange((corners @ direction).min(), (corners @ direction).max() + 1e-9, SPACING)
    rows, out, k = [], [], 0
    for c in sorted(set(offsets)):
        xy = (c * normal + s[:, None] * direction)[:, :2]
        out.append(xy)
        rows.append((k, k + len(xy)))
        k += len(xy)
    return np.concatenate(out), rows


def chord_worst(judge: FaceDistances, polylines) -> float:
    """Worst |distance - R'| (mm) of the midpoints of consecutive centres where the ball
    lies wholly over a face: what a straight move between two points leaves or cuts."""
    mids = [0.5 * (pl[1:] + pl[:-1]) for pl in polylines if len(pl) > 1]
    dev = judge.measure(mids, check=0)
    return float(np.nanmax(np.abs(dev.signed[dev.over])))


def compare(name: str, shape, faces: list[int], tols: list[float], *, angle: float = 0.0,
            stepover: float = 1.0, margin: float = 0.5, source: str = "<shape>") -> dict:
    """Every figure of one case (see the module doc), and the polylines for the picture."""
    run = cadcnc_finish(shape, faces, radius=R, stepover=stepover, angle=angle, source=source)
    part = cadcnc.Part(shape, source=source)  # for the faces only (not timed)
    topods = [part.face(n).topods for n in faces]
    judge = FaceDistances(topods, R, margin=margin)
    t0 = clock()
    dev = judge.measure(run.polylines)
    devs = {"cadcnc": dev.per_line()}
    rows = {"cadcnc": dict(dev.summary(), points=run.points,
                           chord=chord_worst(judge, run.polylines),
                           seconds=run.seconds, seconds_part=run.seconds_part,
                           seconds_gate=run.seconds_gate, gate_ok=run.gate_ok,
                           skipped=run.skipped, parts=run.parts,
                           us_per_point=1e6 * run.seconds / run.points,
                           passes=len(run.polylines))}
    lines = {"cadcnc": run.polylines}
    print(f"{name}: cadcnc {run.points} points in {run.seconds:.2f} s, measured in "
          f"{clock() - t0:.1f} s", file=sys.stderr)
    xy, spans = ocl_points(topods, run.offsets, angle)
    for tol in tols:
        tris, mesh_s = tessellate(topods, tol)
        ocl = run_ocl(tris, xy, R, threads=1)
        polys = [ocl.centres[a:b] for a, b in spans]
        total = mesh_s + sum(ocl.seconds.values())
        key = f"ocl {tol:g}"
        dev = judge.measure(polys)
        devs[key] = dev.per_line()
        rows[key] = dict(dev.summary(), triangles=int(len(tris)),
                         chord=chord_worst(judge, polys),
                         points=int(len(xy)), seconds=total, seconds_mesh=mesh_s,
                         seconds_ocl=ocl.seconds, threads=ocl.threads,
                         us_per_point=1e6 * total / len(xy))
        lines[key] = polys
        print(f"{name}: {key}: {len(tris)} triangles, {total:.2f} s", file=sys.stderr)
    return dict(name=name, faces=faces, angle=angle, stepover=stepover, margin=margin,
                offsets=run.offsets, rows=rows, lines=lines, devs=devs)


def _ratio(a: float, b: float) -> str:
    return "-" if b <= 0 else f"{a / b:.3g}x"


def table(case: dict) -> str:
    """The markdown table of one case: every row, and OCL / cadcnc ratios."""
    rows, ours = case["rows"], case["rows"]["cadcnc"]
    out = [f"**{case['name']}** (faces {case['faces']}, {ours['passes']} cuts, "
           f"counted {ours['counted']} of {ours['points']} cadcnc points)", "",
           "| | triangles | points | worst dev. | p50 | p99 | gouge side | leave side "
           "| chord midpoints, worst | time per point | worst dev. / cadcnc's "
           "| time per point / cadcnc's |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for key, r in rows.items():
        out.append(f"| {key} | {r.get('triangles', '-')} | {r['points']} | {r['max']:.2e} mm "
                   f"| {r['p50']:.1e} | {r['p99']:.1e} | {r['gouge']:.1e} | {r['leave']:.1e} "
                   f"| {r['chord']:.1e} | {r['us_per_point']:.1f} µs "
                   f"| {_ratio(r['max'], ours['max'])} "
                   f"| {_ratio(r['us_per_point'], ours['us_per_point'])} |")
    if ours["seconds_gate"] is not None:
        out += ["", f"cadcnc: {ours['seconds']:.2f} s for the program (reading the part "
                f"{ours['seconds_part']:.3f} s); the gouge gate (gate_program) "
                f"{ours['seconds_gate']:.2f} s ({1e6 * ours['seconds_gate'] / ours['points']:.1f}"
                f" µs per point), {'passed' if ours['gate_ok'] else 'REFUSED'}."]
    if ours.get("parts"):
        out += ["", "Inside cadcnc.finish: " + "; ".join(
            f"{what} {sec:.2f} s ({calls} calls)" for what, (sec, calls) in ours["parts"].items())]
    for key, r in rows.items():
        if "seconds_mesh" in r:
            out += ["", f"{key}: BRepMesh {r['seconds_mesh']:.2f} s, STLSurf "
                    f"{r['seconds_ocl']['stl']:.2f} s, appending points "
                    f"{r['seconds_ocl']['append']:.2f} s, BatchDropCutter.run "
                    f"{r['seconds_ocl']['run']:.2f} s ({r['threads']} thread)."]
    if ours.get("skipped"):
        out += ["", "Not cut: " + "; ".join(ours["skipped"])]
    return "\n".join(out)


def picture(case: dict, path: Path) -> None:
    """|Deviation| along the middle pass (cadcnc's centres and chord midpoints, OCL's
    centres), and histograms of |deviation| over every counted centre."""
    import matplotlib  # noqa: PLC0415 - 0.5 s, only when a picture is asked for
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.4))
    direction, _ = plane_frame(case["angle"])
    mid = len(case["lines"]["cadcnc"]) // 2
    planes = sorted(set(case["offsets"]))
    floor = 1e-16
    bins = np.logspace(-16, -1, 121)
    for k, (key, polys) in enumerate(case["lines"].items()):
        colour = "C2" if key == "cadcnc" else f"C{k - 1}"
        j = mid if key == "cadcnc" else planes.index(case["offsets"][mid])
        signed, over = case["devs"][key][j]
        shown = np.where(over, np.maximum(np.abs(signed), floor), np.nan)
        ax1.semilogy(polys[j] @ direction, shown, lw=0.8, color=colour, label=f"{key} centres")
        counted = np.concatenate([np.abs(d[o]) for d, o in case["devs"][key]])
        ax2.hist(np.maximum(counted, floor), bins=bins, histtype="step", color=colour,
                 label=f"{key}: worst {counted.max():.1e} mm")
    ax1.axhline(case["rows"]["cadcnc"]["chord"], color="C2", ls="--", lw=0.8,
                label="cadcnc chord midpoints, worst")
    ax1.set_xlabel("position along the pass (mm)")
    ax1.set_ylabel("|distance - R'| (mm)")
    ax1.set_title(f"{case['name']}: pass {mid + 1} (plane offset {case['offsets'][mid]:.3f} mm)",
                  fontsize=10)
    ax1.legend(fontsize=8)
    ax2.set_xscale("log")
    ax2.set_xlabel("|distance - R'| (mm), centres with the ball wholly over a face")
    ax2.set_ylabel("ball centres")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def slab_case(tols: list[float]) -> dict:
    shape = freeform_slab.slab_shape()
    part = cadcnc.Part(shape, source="freeform slab")
    return compare("free-form slab 80 x 60 mm", shape, [freeform_slab.top_face_number(part)],
                   tols, source="freeform slab")


def fixture_cases(tols: list[float], names=None) -> list[dict]:
    facts = json.loads((ROOT / "fixtures" / "finish_fixtures.json").read_text())
    out = []
    for name, f in facts.items():
        if names and name not in names:
            continue
        path = ROOT / "fixtures" / f["file"]
        part = cadcnc.load_step(path)
        out.append(compare(name, part.shape, list(f["faces"]), tols, source=str(path)))
    return out


def warm_up() -> None:
    """Load (or compile) the numba kernels on a throwaway part with three passes, so the
    timed runs measure the steady state (importing and loading the kernels are a
    process's one-time cost, about 1-2 s warm, 30-60 s on a cold cache)."""
    shape = freeform_slab.slab_shape()
    part = cadcnc.Part(shape, source="warm-up")
    cadcnc.finish(part, [freeform_slab.top_face_number(part)], radius=R, stepover=25.0,
                  feed=FEED, period=PERIOD)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--slab", action="store_true")
    ap.add_argument("--fixtures", nargs="*", metavar="NAME",
                    help="the finishing fixtures (all, or those named)")
    ap.add_argument("--tol", type=float, nargs="+", default=[1e-2, 1e-3])
    ap.add_argument("--json", type=Path)
    ap.add_argument("--png", type=Path, default=ROOT / "docs" / "img" / "finish_vs_ocl.png")
    args = ap.parse_args(argv)
    t0 = clock()
    warm_up()
    print(f"warm-up {clock() - t0:.1f} s", file=sys.stderr)
    cases = []
    if args.slab or args.fixtures is None:
        cases.append(slab_case(args.tol))
        picture(cases[-1], args.png)
    if args.fixtures is not None:
        cases += fixture_cases(args.tol, args.fixtures)
    for case in cases:
        print(table(case), end="\n\n")
    if args.json:
        keep = [{k: v for k, v in c.items() if k not in ("lines", "devs")} for c in cases]
        args.json.write_text(json.dumps(keep, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
