"""Regenerate the tables of docs/performance.md from one run of the benchmarks.

    .venv/bin/python -m benchmarks perf            # --quick: about 3 minutes on 2 cores
    .venv/bin/python -m benchmarks perf --full     # long runs (coverage of every pair...)
    .venv/bin/python -m benchmarks perf --only kernel --no-write

Each section runs its benchmark in this process (ratios against a reference run in the
same process, as the benchmarks print them) and replaces the text of docs/performance.md
between its markers ``<!-- perf:NAME:start -->`` and ``<!-- perf:NAME:end -->``; the
sections not run keep their text. Sections:

- ``kernel``: ``benchmarks.kernel.bench_kernel`` on its four fixture pairs (per step, loop,
  latency, whole path against GeomAPI_IntSS, memory, landing);
- ``operations``: ``cadcnc.finish`` on the free-form slab (``benchmarks.finishing``; with
  ``--ocl`` OpenCAMLib's drop-cutter beside it, needs ``pip install -e '.[bench]'``), the
  gouge gate (``benchmarks.kernel.bench_gate``), ``cadcnc.run`` of a Pencil on fixtures and on any
  ``--part``;
- ``coverage``: path coverage judged independently (``benchmarks.coverage.pair_coverage``):
  every concave pair of pocket.step at R 3 (quick), of every fixture at R 3 and R 2 (full).
"""

from __future__ import annotations

import argparse
import importlib.metadata
import importlib.util
import multiprocessing
import os
import platform
import sys
import time
from datetime import date
from pathlib import Path

import numpy as np

from benchmarks import FIXTURES, ROOT

DOC = ROOT / "docs" / "performance.md"
SECTIONS = ("kernel", "operations", "coverage")
MODES = {  # what --quick (the default) and --full run
    "quick": {"steps": 20_000, "streamed": 100_000, "reps": 15,
              "gate": [("bspline_boss", 70_000)], "pencil": ["step_slot", "fillet_pocket"],
              "coverage": ["pocket.step"], "radii": [3.0]},
    "full": {"steps": 100_000, "streamed": 1_000_000, "reps": 15,
             "gate": [("torus_cone", 70_000), ("bspline_boss", 70_000)],
             "pencil": ["pocket", "fillet_pocket", "step_slot", "step_block"],
             "coverage": None, "radii": [3.0, 2.0]},
}
clock = time.perf_counter


def log(msg: str) -> None:
    print(f"perf: {msg}", file=sys.stderr, flush=True)


def _row(label: str, cells) -> str:
    return f"| {label} | " + " | ".join(cells) + " |"


# --- kernel ---------------------------------------------------------------------------

def kernel(mode: dict) -> dict:
    """The per-step and whole-path tables, memory and landing (bench_kernel's functions)."""
    from benchmarks.kernel import bench_kernel as bk  # noqa: PLC0415 - OCCT, numba: 2 s
    from benchmarks.kernel.latency import latency, percentiles  # noqa: PLC0415

    cases, fifo = {}, True
    for name, i, j in bk.CASES:
        log(f"kernel: {name} {i},{j}")
        part, plan, job = bk.plan_of(name, i, j)
        bk.stepper(plan, job).run()                                 # warm-up (JIT load)
        d2 = bk.bare_d2(plan)
        ref = bk.step_times(bk.stepper(plan, job, compiled=False), 2000)
        fast = bk.step_times(bk.stepper(plan, job, end=False), 20_000)
        cold, warm, ss = bk.path_vs_intss(part, i, j, plan, reps=mode["reps"])
        res = latency(lambda: bk.stepper(plan, job, end=False), mode["steps"])
        ratio = {k: (lambda p: p[2] / p[0])(percentiles(v)) for k, v in res.items()
                 if v is not None}
        fifo = fifo and res["kernel"] is not None
        cases[f"{name} {i},{j}"] = {
            "step": float(np.median(fast)), "d2": d2, "ref": float(np.median(ref)),
            "loop": bk.loop_per_cycle(plan, job, 200_000), "lat": ratio,
            "steps": len(res["raw"]), "cold": cold, "warm": warm, "ss": ss}
        if name == bk.CASES[0][0]:
            memory = bk.memory(plan, job, 100_000, mode["streamed"])
    landings = []
    for name, i, j, guard in bk.LANDINGS:
        _, plan, job = bk.plan_of(name, i, j)
        landings.append((name, i, j, *bk.landing(plan, job, guard)))

    c = list(cases.values())
    head = ["| | " + " | ".join(cases) + " |", "|---|" + "---|" * len(cases)]
    own = "kernel" if fifo else "cpu"
    step = head + [
        _row("`Stepper.step` compiled, record off, p50", [f"{x['step']:.2f} µs" for x in c]),
        _row("the same / two bare OCCT D2 from Python", [f"{x['step'] / x['d2']:.2f}x" for x in c]),
        _row("reference step / compiled step", [f"{x['ref'] / x['step']:.1f}x" for x in c]),
        _row("loop compiled (`Stepper.run`), per cycle", [f"{x['loop']:.2f} µs" for x in c]),
        _row("latency p99.9 / p50, kernel's own work" if fifo else
             "latency p99.9 / p50, thread CPU time (SCHED_FIFO not permitted)",
             [f"{x['lat'][own]:.2f}" for x in c]),
        _row("latency p99.9 / p50, normal scheduling", [f"{x['lat']['raw']:.2f}" for x in c]),
    ]
    per, growth, streamed = memory
    step += ["", f"Latency over {c[0]['steps']:,} steps per pair, GC off.", "",
             f"- **Memory**: {per:.0f} bytes per cycle traced with the record on; {growth:,} "
             f"bytes of growth over {streamed:,} streamed cycles with it off."]
    for name, i, j, land, median, reason, trials in landings:
        step.append(f"- **Landing** ({name} {i},{j}): `{reason}` in {trials} trial cycles, "
                    f"{land:.1f} µs = {land / median:.0f}x the median step ({median:.2f} µs).")
    whole = head + [
        _row("IntSS", [f"{x['ss']['cpu'] / 1000:.2f} ms" for x in c]),
        _row("whole path, cold", [f"{x['cold']['cpu'] / 1000:.2f} ms" for x in c]),
        _row("**speed-up, cold**", [f"**{x['ss']['cpu'] / x['cold']['cpu']:.1f}x**" for x in c]),
        _row("whole path, warm", [f"{x['warm']['cpu'] / 1000:.2f} ms" for x in c]),
        _row("speed-up, warm", [f"{x['ss']['cpu'] / x['warm']['cpu']:.1f}x" for x in c]),
    ]
    return {"kernel-step": "\n".join(step),
            "kernel-whole": "\n".join(whole) + f"\n\nCPU time, the minimum of {mode['reps']} "
            "interleaved runs."}


# --- operations -----------------------------------------------------------------------

def finishing(ocl: bool) -> list[str]:
    """The slab row: cadcnc.finish's time per point; OpenCAMLib's beside it with ``ocl``."""
    import cadcnc  # noqa: PLC0415
    from benchmarks.finishing import finish_vs_ocl as fv  # noqa: PLC0415
    from benchmarks.finishing import freeform_slab

    log("operations: finish on the free-form slab")
    fv.warm_up()
    shape = freeform_slab.slab_shape()
    faces = [freeform_slab.top_face_number(cadcnc.Part(shape, source="freeform slab"))]
    if not ocl:
        run = fv.cadcnc_finish(shape, faces, radius=fv.R, stepover=1.0, angle=0.0,
                               source="freeform slab")
        return [f"| `cadcnc.finish` on the free-form slab (80 x 60 mm), R 3, stepover 1 mm "
                f"| {1e6 * run.seconds / run.points:.1f} µs per point ({run.points:,} points, "
                f"{run.seconds:.2f} s); the gate {run.seconds_gate:.2f} s, "
                f"{'passed' if run.gate_ok else 'REFUSED'} "
                "| [finish.md](finish.md#current-figures) |"]
    case = fv.compare("free-form slab", shape, faces, [1e-3], source="freeform slab")
    ours, theirs = case["rows"]["cadcnc"], case["rows"]["ocl 0.001"]
    return [f"| `cadcnc.finish` on the free-form slab (80 x 60 mm), R 3, stepover 1 mm "
            f"| {ours['us_per_point']:.1f} µs per point, worst deviation {ours['max']:.1e} mm "
            f"(OpenCAMLib at a 1e-3 mm mesh: {theirs['us_per_point']:,.0f} µs, "
            f"{theirs['max']:.1e} mm) | [finish.md](finish.md#current-figures) |"]


def gate(cases: list) -> list[str]:
    from benchmarks.kernel import bench_gate  # noqa: PLC0415

    rows = []
    for case, cycles in cases:
        log(f"operations: the gate on {case}")
        m = bench_gate.measure(case, cycles)
        i, j = m["faces"]
        rows.append(f"| the gate, {case} {i}/{j}, {m['cycles']:,} cycles | {m['gate_s']:.1f} s "
                    f"(the path {m['path_s']:.1f} s), {'passed' if m['ok'] else 'REFUSED'} "
                    "| [reliability.md](reliability.md#current-figures) |")
    return rows


def pencil(names: list[str], parts: list[Path]) -> list[str]:
    import cadcnc  # noqa: PLC0415

    rows = []
    for path in [FIXTURES / f"{n}.step" for n in names] + parts:
        log(f"operations: pencil on {path.name}")
        t0 = clock()
        part = cadcnc.load_step(path)
        program = cadcnc.run(part, cadcnc.Job(cadcnc.Tool(3.0), 1500.0, 0.004,
                                              cadcnc.Pencil(), source=part.source))
        wall = clock() - t0
        skipped = f", {len(program.skipped)} skipped" if program.skipped else ""
        rows.append(f"| `cadcnc.run` of a Pencil on {path.name} ({len(part.faces)} faces), R 3 "
                    f"| {wall:.1f} s wall, {len(program.cuts)} cuts{skipped} "
                    "| [pencil.md](pencil.md#current-figures) |")
    return rows


def operations(mode: dict, ocl: bool, parts: list[Path]) -> dict:
    rows = ["| run | figure | page |", "|---|---|---|"]
    rows += finishing(ocl) + gate(mode["gate"]) + pencil(mode["pencil"], parts)
    return {"operations": "\n".join(rows)}


# --- coverage -------------------------------------------------------------------------

def coverage(mode: dict, workers: int) -> dict:
    """Covered / feasible over the fixtures' pairs, as pair_coverage.py measures it."""
    from benchmarks.coverage import pair_coverage as pc  # noqa: PLC0415

    files = ([FIXTURES / n for n in mode["coverage"]] if mode["coverage"]
             else sorted(FIXTURES.glob("*.step")))
    tasks = []
    for f in files:
        pairs, _ = pc.pairs_of(str(f))
        for radius in mode["radii"]:
            for faces in pairs:
                tasks.append({"step": str(f), "name": f.name, "faces": faces, "via": "cli",
                              "radius": radius, "feed": 1500.0, "period": "4ms",
                              "timeout": 300.0, "max_samples": None, "check_points": 100})
    log(f"coverage: {len(tasks)} pair runs on {len(files)} fixtures, {workers} workers")
    records = []
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        for k, rec in enumerate(pool.imap(pc.run_pair, tasks, chunksize=1), 1):
            records.append(rec)
            log(f"coverage: [{k}/{len(tasks)}] {rec['part']} {rec['faces']} R {rec['radius']}:"
                f" {rec['covered']}/{rec['feasible']} ({rec['seconds']} s)")
    what = (f"every concave pair of {', '.join(mode['coverage'])}" if mode["coverage"]
            else "every concave pair of every fixture")
    rows = ["| set | R | pairs | covered / feasible | unreachable from +Z, covered / all "
            "| silent-bad cuts | crashes | judge errors |", "|---|---|---|---|---|---|---|---|"]
    for radius in mode["radii"]:
        rs = [r for r in records if r["radius"] == radius]
        c, f = sum(r["covered"] for r in rs), sum(r["feasible"] for r in rs)
        cu = sum(r.get("covered_unreachable", 0) for r in rs)
        u = sum(r.get("unreachable", 0) for r in rs)
        runs = [run for r in rs for run in r.get("runs", [])]
        bad = sum(bool(r.get("path_check", {}).get("bad")) for r in rs)
        crashes = sum(run["outcome"] in ("crash", "timeout") for run in runs)
        errors = sum("error" in r for r in rs)
        pct = f" ({100.0 * c / f:.2f} %)" if f else ""
        rows.append(f"| {what} | {radius:g} | {len(rs)} | {c} / {f}{pct} | {cu} / {u} | {bad} "
                    f"| {crashes} | {errors} |")
    return {"coverage": "\n".join(rows)}


# --- the document ---------------------------------------------------------------------

def replace_block(text: str, name: str, body: str) -> str:
    start, end = f"<!-- perf:{name}:start -->", f"<!-- perf:{name}:end -->"
    if start not in text or end not in text:
        raise SystemExit(f"perf: {DOC.name} has no markers {start} ... {end}")
    head, rest = text.split(start, 1)
    return f"{head}{start}\n{body}\n{end}{rest.split(end, 1)[1]}"


def versions() -> str:
    def v(name: str) -> str:
        try:
            return importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            return "?"
    return (f"Python {platform.python_version()}, numba {v('numba')}, cadquery {v('cadquery')} "
            f"(OCP {v('cadquery-ocp')})")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks perf",
                                 description=__doc__.split("\n")[0])
    size = ap.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true", help="the default: a few minutes")
    size.add_argument("--full", action="store_true",
                      help="1e5 latency steps, 1e6 streamed cycles, both gate cases, every "
                      "pencil fixture, coverage of every fixture pair at R 3 and R 2 "
                      "(about an hour on 2 cores), OpenCAMLib when installed")
    ap.add_argument("--only", nargs="+", choices=SECTIONS, default=list(SECTIONS))
    ap.add_argument("--ocl", action=argparse.BooleanOptionalAction, default=None,
                    help="OpenCAMLib beside cadcnc.finish (default: with --full, when installed)")
    ap.add_argument("--part", type=Path, action="append", default=[],
                    help="a STEP part for a pencil row as well (e.g. OCCT's r0901_ec.stp)")
    ap.add_argument("--workers", type=int, default=2, help="coverage processes (default 2)")
    ap.add_argument("--no-write", action="store_true", help="print the tables only")
    args = ap.parse_args(argv)
    name = "full" if args.full else "quick"
    mode = MODES[name]
    has_ocl = importlib.util.find_spec("opencamlib") is not None  # not imported: see ocl_worker
    ocl = (args.full and has_ocl) if args.ocl is None else args.ocl
    if ocl and not has_ocl:
        raise SystemExit("perf: --ocl needs opencamlib: pip install -e '.[bench]'")
    t0 = clock()
    blocks = {}
    if "kernel" in args.only:
        blocks.update(kernel(mode))
    if "operations" in args.only:
        blocks.update(operations(mode, ocl, args.part))
    if "coverage" in args.only:
        blocks.update(coverage(mode, max(1, args.workers)))
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    blocks["run"] = (f"Regenerated by `python -m benchmarks perf --{name}"
                     f"{' --only ' + ' '.join(args.only) if args.only != list(SECTIONS) else ''}`"
                     f" on {date.today().isoformat()} in {clock() - t0:.0f} s: {os.cpu_count()} "
                     f"cores (load average {load}), {versions()}.")
    for key, body in blocks.items():
        print(f"<!-- perf:{key} -->\n{body}\n")
    if not args.no_write:
        text = DOC.read_text()
        for key, body in blocks.items():
            text = replace_block(text, key, body)
        DOC.write_text(text)
        log(f"wrote {len(blocks)} blocks of {DOC.relative_to(ROOT)}")
    return 0
