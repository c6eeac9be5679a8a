"""The gate's pace and every core (issue 24), measured in one process run.

For each case (the free-form slab of benchmarks/finishing/freeform_slab.py finished at
R 3, stepover 1; a STEP part's pencil, e.g. r0901_ec R 3), as the CLI runs it:

- the computation at ``jobs=1`` (wall and CPU);
- the gate before (the reference gate: cut-back, then the program gate on the moves
  written) and after (the shared, bounded gate at ``jobs=1``), each with its ratio to
  the computation; the verdicts compared cut by cut;
- computation plus gate at ``jobs=2`` against ``jobs=1`` (wall), and whether the JSON and
  G-code are the same bytes;
- the scaling beyond 2 estimated from the per-task times of the ``jobs=1`` run (the
  planes or the pairs' corners, and the gate's cuts: longest task first on N workers,
  plus the serial rest).

    nice python -m benchmarks.pace.bench_pace [--slab] [--pencil PART.stp] [--radius 3]
        [--json OUT]

Loaded machines give noisy walls: os.getloadavg() is printed before and after.
"""

from __future__ import annotations

import argparse
import heapq
import json
import os
import tempfile
import time

import cadcnc
from benchmarks.finishing import freeform_slab
from cadcnc.core.job import Job, Pencil, Raster, Tool
from cadcnc.io.gcode import blend_for
from cadcnc.io.outputs import render
from cadcnc.io.program_gcode import program_written_moves
from cadcnc.ops.common import safe_height
from cadcnc.ops.run import cut_back_gap
from cadcnc.parallel.pool import kept_pools
from cadcnc.verification import gate_program
from cadcnc.verification.cut_back import cut_back
from cadcnc.verification.gate_cache import shared_gates

clock, cpu = time.perf_counter, time.process_time


def slab_case(folder: str) -> tuple[str, Job]:
    """(STEP path, Job): the free-form slab, R 3, stepover 1 mm, angle 0."""
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    path = os.path.join(folder, "freeform_slab.step")
    writer = STEPControl_Writer()
    writer.Transfer(freeform_slab.slab_shape(), STEPControl_AsIs)
    writer.Write(path)
    top = freeform_slab.top_face_number(cadcnc.load_step(path))
    return path, Job(Tool(3.0, 0.0), 1500.0, 0.004, Raster((top,), 1.0, None, 0.0, "zigzag"),
                     source=path)


def pencil_case(path: str, radius: float) -> tuple[str, Job]:
    return path, Job(Tool(radius, 0.0), 1500.0, 0.004, Pencil(None, "climb"), source=path)


def timed(fn):
    """(result, wall s, CPU s of this process)."""
    w, c = clock(), cpu()
    out = fn()
    return out, clock() - w, cpu() - c


def stamps() -> tuple[list, callable]:
    """A progress callback recording when each piece ends (per-task times at jobs=1)."""
    seen: list[float] = [clock()]
    return seen, (lambda *a: seen.append(clock()))


def gate(program, part, *, jobs: int, reference: bool):
    """The CLI's gating: cut-back, then the program gate on the G-code's moves."""
    gcode = dict(tolerance=None, tool_tip=False, blend=blend_for(program.job.tolerances.gouge))
    z, join = safe_height(part, program.job), cut_back_gap(program.job)
    seen, tick = stamps()
    back = cut_back(program, part, z, join, jobs=jobs, reference=reference, progress=tick)
    moves = program_written_moves(back, **gcode)
    result = gate_program(back, part, moves=moves, blend_mm=gcode["blend"], jobs=jobs,
                          reference=reference)
    return back, result, gcode, [b - a for a, b in zip(seen, seen[1:])]


def run_case(name: str, path: str, job: Job) -> dict:
    out: dict = {"case": name, "load_before": os.getloadavg()}
    part = cadcnc.load_step(path)
    seen, tick = stamps()
    program, out["compute_s"], out["compute_cpu_s"] = timed(
        lambda: cadcnc.run(part, job, processes=1, progress=tick))
    tasks = [b - a for a, b in zip(seen, seen[1:])]
    out["points"] = sum(len(c.points) for c in program.cuts)
    (_, ref, _, _), out["gate_ref_s"], out["gate_ref_cpu_s"] = timed(
        lambda: gate(program, cadcnc.load_step(path), jobs=1, reference=True))
    fresh = cadcnc.load_step(path)
    with shared_gates(fresh):
        (back, new, gcode, gate_tasks), out["gate_s"], out["gate_cpu_s"] = timed(
            lambda: gate(program, fresh, jobs=1, reference=False))
    out["same_verdicts"] = [(r.ok, r.message) for r in ref.results] == \
        [(r.ok, r.message) for r in new.results] and all(
        abs(a.depth_mm - b.depth_mm) <= 1e-9 for a, b in zip(ref.results, new.results))
    for k in ("gate_ref", "gate"):
        out[f"{k}_ratio"] = out[f"{k}_cpu_s"] / out["compute_cpu_s"]
    files1 = [render(back, f"p{s}", fresh, "", **gcode) for s in (".json", ".ngc")]
    part2 = cadcnc.load_step(path)
    t0 = clock()
    with shared_gates(part2), kept_pools():
        program2 = cadcnc.run(part2, job, processes=2)
        back2, _, gcode2, _ = gate(program2, part2, jobs=2, reference=False)
    out["jobs2_s"] = clock() - t0
    out["jobs1_s"] = out["compute_s"] + out["gate_s"]
    out["speedup_2"] = out["jobs1_s"] / out["jobs2_s"]
    out["same_bytes"] = files1 == [render(back2, f"p{s}", part2, "", **gcode2)
                                   for s in (".json", ".ngc")]
    serial = out["compute_s"] - sum(tasks)
    out["estimated_speedup"] = {n: out["jobs1_s"] / (serial + makespan(tasks, n)
                                                     + makespan(gate_tasks, n)
                                                     + out["gate_s"] - sum(gate_tasks))
                                for n in (2, 4, 8, 16, 32)}
    out["tasks"], out["gate_tasks"] = len(tasks), len(gate_tasks)
    out["load_after"] = os.getloadavg()
    return out


def makespan(times: list[float], workers: int) -> float:
    """Longest-first scheduling of ``times`` on ``workers``: when the last one ends."""
    loads = [0.0] * workers
    for t in sorted(times, reverse=True):
        heapq.heapreplace(loads, loads[0] + t)
    return max(loads, default=0.0)


def report(r: dict) -> str:
    est = ", ".join(f"{n}: {s:.2f}x" for n, s in r["estimated_speedup"].items())
    return "\n".join([
        f"{r['case']}: {r['points']} points; load {r['load_before']} -> {r['load_after']}",
        f"  computation (jobs 1)   {r['compute_s']:.1f} s wall, {r['compute_cpu_s']:.1f} s CPU",
        f"  gate before (reference) {r['gate_ref_s']:.1f} s wall, {r['gate_ref_cpu_s']:.1f} s "
        f"CPU = {r['gate_ref_ratio']:.2f} x the computation",
        f"  gate after  (jobs 1)    {r['gate_s']:.1f} s wall, {r['gate_cpu_s']:.1f} s CPU = "
        f"{r['gate_ratio']:.2f} x the computation; {r['gate_ref_cpu_s'] / r['gate_cpu_s']:.1f}x "
        f"less; same verdicts: {r['same_verdicts']}",
        f"  jobs 2 vs 1 (computation + gate, wall): {r['jobs1_s']:.1f} s -> {r['jobs2_s']:.1f} s"
        f" = {r['speedup_2']:.2f}x; same bytes: {r['same_bytes']}",
        f"  estimated from {r['tasks']} + {r['gate_tasks']} task times: {est}"])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--slab", action="store_true")
    ap.add_argument("--pencil", metavar="PART.stp")
    ap.add_argument("--radius", type=float, default=3.0)
    ap.add_argument("--json", metavar="OUT")
    args = ap.parse_args(argv)
    results = []
    with tempfile.TemporaryDirectory() as folder:
        if args.slab or not args.pencil:
            results.append(run_case("free-form slab finish", *slab_case(folder)))
            print(report(results[-1]), flush=True)
        if args.pencil:
            results.append(run_case(f"{os.path.basename(args.pencil)} pencil R "
                                    f"{args.radius:g}", *pencil_case(args.pencil, args.radius)))
            print(report(results[-1]), flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1, default=float)


if __name__ == "__main__":
    main()
