"""Waterline finishing against OpenCAMLib's Waterline and AdaptiveWaterline (issue 26).

The same faces (fixtures/wl_*.step, fixtures/waterline_fixtures.json), the same levels
(cadcnc's plan at a 2 mm stepdown), ball R as in tests/ops/test_waterline.py, 0.1 mm point
spacing (cadcnc's step f = F Ts; OCL's fibre sampling 0.1 mm, AdaptiveWaterline's finest
0.01 mm), OCL on OCCT tessellations of the selected faces at ``--tol`` (1e-2, 1e-3 mm),
one thread, in a subprocess (ocl_waterline_worker.py). Measured:

- the worst deviation of loop points from the exact offset of the faces (OCCT's
  distance, |d - R'|), counted where the ball lies wholly over a face
  (finish_bench_tools.FaceDistances, as for raster);
- loops found against loops expected: OCCT's section of the offset faces at the level
  (closed and open wires); cadcnc's cuts joined into chains; OCL's loops (round the
  mesh's free edges for an open piece), and their runs over the faces;
- seconds per level and per loop point. OCL's span: tessellation, STLSurf and its runs.
  cadcnc's like-for-like span ("loops"): from reading the STEP file to the last level's
  loops (face samples, critical heights, levels, OCCT's offset sections, the loops with
  their guard and self-check); its whole program also (links and the uncut report; the
  gate apart). Modules are imported before the clock starts (OCL's import is not timed
  either), and an untimed first run loads numba's cached code (``--cold``: no such run).

    python -m benchmarks.finishing.waterline_vs_ocl [--fixtures dome wall boss]
        [--tol 1e-2 1e-3] [--json OUT] [--png docs/img/waterline_vs_ocl.png]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import cadcnc
from benchmarks import ROOT
from benchmarks.finishing.finish_bench_tools import FaceDistances, tessellate
from cadcnc.geometry.offset_section import loop_count, offset_face
from cadcnc.ops.finish.shortcut import finish
from cadcnc.verification import gate_program

FIXTURES = json.loads((ROOT / "fixtures" / "waterline_fixtures.json").read_text())
RADIUS = {"dome": 3.0, "wall": 3.0, "boss": 2.0}
STEPDOWN, SAMPLING, MIN_SAMPLING = 2.0, 0.1, 0.01
clock = time.perf_counter


def chains(polylines, join=1e-6) -> int:
    """How many chains the polylines (in order) make, each next starting at the last end."""
    count, last = 0, None
    for p in polylines:
        if last is None or np.linalg.norm(p[0] - last) > join:
            count += 1
        last = p[-1]
    return count


def runs(over: np.ndarray, closed: bool = True) -> int:
    """Runs of True in a loop's ``over`` (N,) (cyclic when ``closed``)."""
    if over.all():
        return 1
    starts = int(np.sum(over & ~np.roll(over, 1))) if closed else int(
        over[0] + np.sum(over[1:] & ~over[:-1]))
    return starts


def cadcnc_run(name: str, stepdown: float):
    """(part, program, times, levels, per-level polylines) of cadcnc's waterline; times:
    (program s, loops s, program CPU s, loops CPU s). Loops: from reading the part to the
    last level's loops (samples, critical heights, levels, OCCT's sections, loops; OCL's
    span: tessellation, STLSurf, runs); program: also links and the uncut report."""
    marks = []

    def progress(done, total, what):
        if done == total and not marks:
            marks.append((clock(), time.process_time()))
    t0, c0 = clock(), time.process_time()
    part = cadcnc.load_step(ROOT / "fixtures" / FIXTURES[name]["file"])
    prog = finish(part, FIXTURES[name]["faces"], radius=RADIUS[name],
              strategy="waterline", stepdown=stepdown, progress=progress)
    seconds, cpu = clock() - t0, time.process_time() - c0
    levels = sorted({round(float(c.points[0, 2]), 9) for c in prog.cuts}, reverse=True)
    per = {z: [c.points for c in prog.cuts if abs(c.points[0, 2] - z) < 1e-6] for z in levels}
    return part, prog, (seconds, marks[0][0] - t0, cpu, marks[0][1] - c0), levels, per


def ocl_run(triangles, levels, radius, adaptive: bool) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = os.path.join(tmp, "in.npz"), os.path.join(tmp, "out.npz")
        np.savez(src, triangles=triangles, levels=np.array(levels), radius=radius,
                 length=50.0, sampling=SAMPLING, min_sampling=MIN_SAMPLING,
                 adaptive=int(adaptive), threads=1)
        subprocess.run([sys.executable, "-m", "benchmarks.finishing.ocl_waterline_worker",
                        src, dst], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        out = np.load(dst)
        pts, sizes, level_of = out["points"], out["sizes"], out["level_of"]
        cuts = np.cumsum([0, *sizes])
        loops = [pts[a:b] for a, b in zip(cuts[:-1], cuts[1:])]
        return dict(loops=loops, level_of=level_of, seconds=out["seconds"].tolist(),
                    stl=float(out["stl"]), cpu=float(out["cpu"]))


def compare(name: str, tols, stepdown: float = STEPDOWN) -> dict:
    """Every figure of one fixture (module doc)."""
    part, prog, (seconds, loops_s, cpu, loops_cpu), levels, per = cadcnc_run(name, stepdown)
    t0 = clock()
    gate = gate_program(prog, part)
    gate_s = clock() - t0
    faces = [part.face(f).topods for f in FIXTURES[name]["faces"]]
    rp = RADIUS[name]
    dist = FaceDistances(faces, rp)
    offs = [offset_face(f, rp) for f in faces]
    expected = [sum(loop_count(offs, z)) for z in levels]
    mine = dist.measure([c.points for c in prog.cuts]).summary()
    points = sum(len(c.points) for c in prog.cuts)
    row = dict(fixture=name, radius=rp, levels=levels, expected=expected,
               found=[chains(per[z]) for z in levels],
               cadcnc=dict(seconds=seconds, points=points, deviation=mine,
                           loops_s=loops_s, per_level_s=loops_s / len(levels),
                           per_point_us=1e6 * loops_s / points,
                           program_per_point_us=1e6 * seconds / points,
                           cpu_s=cpu, loops_cpu_s=loops_cpu,
                           gate_ok=bool(gate.ok), gate_s=gate_s),
               ocl={}, cad_level=per[levels[0]])
    for tol in tols:
        tris, mesh_s = tessellate(faces, tol)
        for adaptive in (False, True):
            o = ocl_run(tris, levels, rp, adaptive)
            dev = dist.measure(o["loops"])
            total = mesh_s + o["stl"] + sum(o["seconds"])
            cpu = mesh_s + o["cpu"]   # (the mesh's in this process, unloaded as a rule)
            n = sum(len(p) for p in o["loops"])
            pieces = [0] * len(levels)
            for (signed, over), k in zip(dev.per_line(), o["level_of"]):
                pieces[k] += runs(over) if len(over) else 0
            key = f"{'Adaptive' if adaptive else ''}Waterline {tol:g}"
            row["ocl"][key] = dict(
                triangles=len(tris), seconds=total, mesh_s=mesh_s, points=n, cpu_s=cpu,
                loops=[int(np.sum(o["level_of"] == k)) for k in range(len(levels))],
                pieces_over=pieces, deviation=dev.summary(),
                per_level_s=total / len(levels), per_point_us=1e6 * total / max(n, 1),
                level_loops=[o["loops"][i] for i in np.flatnonzero(o["level_of"] == 0)])
    return row


def table(rows) -> str:
    """The markdown table of docs/waterline.md: cadcnc's time per point over its loops span
    (the program's in brackets), OCL's and its ratio to both."""
    out = ["| fixture | who | worst deviation mm | loops found / expected | s per level "
           "| µs per point (vs cadcnc loops / program) |", "|---|---|---|---|---|---|"]
    for r in rows:
        c = r["cadcnc"]
        out.append(f"| {r['fixture']} | **cadcnc** | {c['deviation']['max']:.1e} | "
                   f"{sum(r['found'])}/{sum(r['expected'])} | {c['per_level_s']:.2f} | "
                   f"**{c['per_point_us']:.0f}** (program {c['program_per_point_us']:.0f}) |")
        for key, o in r["ocl"].items():
            out.append(f"| | OCL {key} | {o['deviation']['max']:.1e} | "
                       f"{sum(o['loops'])} loops, {sum(o['pieces_over'])} over the faces / "
                       f"{sum(r['expected'])} | {o['per_level_s']:.2f} | "
                       f"{o['per_point_us']:.0f} ({o['per_point_us'] / c['per_point_us']:.3g}x"
                       f" / {o['per_point_us'] / c['program_per_point_us']:.3g}x) |")
    return "\n".join(out)


def picture(row, path) -> None:
    """One fixture's top level: cadcnc's loops and OCL's (first mesh), and |deviation|
    histograms."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.8))
    for p in row["cad_level"]:
        a.plot(p[:, 0], p[:, 1], "k-", lw=1.5, label="cadcnc")
    for (key, o), colour in zip(row["ocl"].items(), ("tab:red", "tab:orange", "tab:blue",
                                                       "tab:cyan")):
        for p in o["level_loops"]:
            a.plot(p[:, 0], p[:, 1], ".", ms=1.5, color=colour, label=f"OCL {key}")
        b.bar(key.replace("Waterline ", "WL\n"), o["deviation"]["max"], color=colour)
    b.bar("cadcnc", max(row["cadcnc"]["deviation"]["max"], 1e-16), color="k")
    handles, labels = a.get_legend_handles_labels()
    keep = dict(zip(labels, handles))
    a.legend(keep.values(), keep.keys(), fontsize=7, loc="lower left")
    a.set_aspect("equal")
    a.set_title(f"{row['fixture']}, level z {row['levels'][0]:.2f} mm (ball centres)")
    b.set_yscale("log")
    b.set_ylabel("worst |distance to the faces - R'|, mm (OCCT)")
    b.set_title("worst deviation of loop points, every level")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fixtures", nargs="*", default=list(FIXTURES))
    ap.add_argument("--tol", nargs="*", type=float, default=[1e-2, 1e-3])
    ap.add_argument("--stepdown", type=float, default=STEPDOWN)
    ap.add_argument("--json")
    ap.add_argument("--png")
    ap.add_argument("--cold", action="store_true",
                    help="no untimed first run (numba's cached code loaded inside the clock)")
    args = ap.parse_args(argv)
    if not args.cold and args.fixtures:   # loads numba's cached code, as OCL's is loaded
        cadcnc_run(args.fixtures[0], args.stepdown)
    load = os.getloadavg()
    rows = []
    for name in args.fixtures:   # written as each fixture is done (long runs)
        rows.append(compare(name, args.tol, args.stepdown))
        print(table(rows[-1:]), flush=True)
        if args.png and len(rows) == 1:
            picture(rows[0], args.png)
        if args.json:
            Path(args.json).write_text(json.dumps(dict(
                load=[load, os.getloadavg()], rows=[_plain(r) for r in rows]), indent=1))
    print(f"\nload average at start {load[0]:.2f}, at end {os.getloadavg()[0]:.2f}")
    print(table(rows))
    return 0


def _plain(row: dict) -> dict:
    """The row without its polylines (JSON)."""
    out = {k: v for k, v in row.items() if k != "cad_level"}
    out["ocl"] = {k: {a: b for a, b in o.items() if a != "level_loops"}
                  for k, o in row["ocl"].items()}
    return out


if __name__ == "__main__":
    sys.exit(main())
