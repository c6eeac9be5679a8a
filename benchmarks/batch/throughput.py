"""Throughput of ``cadcnc batch`` (issue 25): pencil on a folder of parts with 1 and 2
workers of the embedded Dask cluster, the scheduling overhead per task, and what the
per-part times predict for more cores and machines. FOLDER: STEP parts, e.g. the public
parts of OCCT's test data (Open-Cascade-SAS/OCCT, ``data/step/``).

    nice .venv/bin/python -m benchmarks.batch.throughput [--parts FOLDER]
        [--radius 3] [--workers 1 2] [--noop 200] [--json OUT]

Both batches run in this process, one after the other, with ``force`` (every part
computed), each part writing program.json and program.ngc. Printed: the machine's load
(``os.getloadavg``) before and after, the wall time of each batch (cluster start
included and apart), parts per hour, the speedup, the per-part seconds, the overhead per
task (a no-op task's round trip through the same cluster, and the batch's wall time
beyond its parts' seconds), and the longest-first schedule of the measured per-part
times on 32 workers (one 32-core machine) and 128 (four such machines).
"""

from __future__ import annotations

import argparse
import heapq
import json
import os
import tempfile
import time
from pathlib import Path

import cadcnc
from benchmarks import ROOT
from cadcnc.batch.engine import connect, run_batch
from cadcnc.batch.task import BatchOperation, BatchPart
from cadcnc.core.tolerances import Tolerances
from cadcnc.io.gcode import blend_for
from cadcnc.pipeline.operate import Settings

STEP_SUFFIXES = (".step", ".stp")


def parts_of(folder: Path, radius: float) -> list[BatchPart]:
    """Pencil R ``radius`` at 1500 mm/min, 4 ms, on every STEP file of ``folder``."""
    tol = Tolerances()
    settings = Settings(gcode=dict(tolerance=None, tool_tip=False, blend=blend_for(tol.gouge)))
    out = []
    for path in sorted(p for p in folder.iterdir() if p.suffix.lower() in STEP_SUFFIXES):
        job = cadcnc.Job(cadcnc.Tool(radius), 1500.0, 0.004, cadcnc.Pencil(),
                         source=str(path))
        op = BatchOperation("pencil", job, ("program.json", "program.ngc"), settings)
        out.append(BatchPart(str(path), (op,)))
    return out


def longest_first(seconds: list[float], workers: int) -> float:
    """The makespan (s) of the tasks ``seconds`` on ``workers``, longest first, each to
    the least loaded worker (overhead not included)."""
    loads = [0.0] * workers
    for t in sorted(seconds, reverse=True):
        heapq.heapreplace(loads, loads[0] + t)
    return max(loads)


def noop_round_trip(workers: int, tasks: int) -> dict:
    """Seconds per no-op task through an embedded cluster of ``workers`` (submitted at
    once, gathered as they end), and the cluster's start time."""
    from benchmarks.batch.noop import noop  # a module the workers import by name

    t0 = time.perf_counter()
    with connect(None, workers, workers) as client:
        t1 = time.perf_counter()
        client.submit(noop, -1).result()     # warm: the worker imports the module
        t2 = time.perf_counter()
        futures = [client.submit(noop, k, pure=False) for k in range(tasks)]
        client.gather(futures)
        t3 = time.perf_counter()
    return {"cluster_start_s": t1 - t0, "per_task_ms": (t3 - t2) / tasks * 1000.0,
            "tasks": tasks, "workers": workers}


def one_batch(parts: list[BatchPart], workers: int) -> dict:
    with tempfile.TemporaryDirectory(prefix="cadcnc-batch-bench-") as out:
        load0 = os.getloadavg()
        t0 = time.perf_counter()
        records = run_batch(parts, out, workers=workers, force=True)
        wall = time.perf_counter() - t0
    return {"workers": workers, "wall_s": wall, "load_before": load0,
            "load_after": os.getloadavg(),
            "parts": {r.part: {"seconds": r.seconds, "cpu_seconds": r.cpu_seconds,
                               "exit": r.exit, "cuts": r.cuts} for r in records}}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", default=str(ROOT.parent / "shared" / "parts"))
    ap.add_argument("--radius", type=float, default=3.0)
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--noop", type=int, default=200, help="no-op tasks for the overhead")
    ap.add_argument("--json", help="write the figures here")
    args = ap.parse_args(argv)
    parts = parts_of(Path(args.parts), args.radius)
    print(f"{len(parts)} parts in {args.parts}, pencil R {args.radius:g}; "
          f"load {os.getloadavg()}", flush=True)
    report = {"noop": noop_round_trip(max(args.workers), args.noop), "runs": []}
    print(f"no-op task: {report['noop']['per_task_ms']:.2f} ms each, cluster start "
          f"{report['noop']['cluster_start_s']:.1f} s", flush=True)
    for n in args.workers:
        run = one_batch(parts, n)
        report["runs"].append(run)
        busy = sum(p["seconds"] for p in run["parts"].values())
        cpu = sum(p["cpu_seconds"] for p in run["parts"].values())
        print(f"{n} worker(s): {run['wall_s']:.1f} s wall, parts' seconds {busy:.1f} "
              f"(CPU {cpu:.1f}), "
              f"{len(parts) / run['wall_s'] * 3600:.0f} parts/h; load "
              f"{run['load_before']} -> {run['load_after']}", flush=True)
    base = report["runs"][0]
    for run in report["runs"][1:]:
        run["speedup"] = base["wall_s"] / run["wall_s"]
        print(f"speedup {run['workers']} vs {base['workers']} worker(s): "
              f"{run['speedup']:.2f}x", flush=True)
    seconds = [p["seconds"] for p in base["parts"].values()]
    cpu = [p["cpu_seconds"] for p in base["parts"].values()]
    for name, p in sorted(base["parts"].items(), key=lambda kv: -kv[1]["seconds"]):
        print(f"  {name}: {p['seconds']:.1f} s ({p['cpu_seconds']:.1f} s CPU), exit "
              f"{p['exit']}, {p['cuts']} cuts")
    report["overhead_per_task_s"] = (base["wall_s"] * base["workers"] - sum(seconds)) \
        / len(seconds)
    report["predicted_s"] = {str(w): longest_first(seconds, w) for w in (1, 2, 32, 128)}
    report["predicted_cpu_s"] = {str(w): longest_first(cpu, w) for w in (1, 2, 32, 128)}
    report["mean_part_cpu_s"] = sum(cpu) / len(cpu)
    report["mean_part_s"] = sum(seconds) / len(seconds)
    print(f"overhead per task (wall x workers - parts' seconds, per part, cluster start "
          f"included): {report['overhead_per_task_s']:.2f} s; longest-first makespan: "
          + ", ".join(f"{w} workers {s:.1f} s" for w, s in report["predicted_s"].items())
          + "; on the parts' CPU seconds (an idle core each): "
          + ", ".join(f"{w} workers {s:.1f} s" for w, s in report["predicted_cpu_s"].items()),
          flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=1))
    return report


if __name__ == "__main__":
    main()
