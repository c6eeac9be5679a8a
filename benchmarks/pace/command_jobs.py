"""``--jobs 2`` against ``--jobs 1``, the whole command as a user runs it (issue 24).

Each command is a new process (start-up, reading the part, the computation, the gate,
writing the JSON and the G-code), timed by the wall clock, the two job counts
interleaved over ``--rounds`` rounds; the outputs of every run must be the same bytes.
Cases: the free-form slab's finish (benchmarks/finishing/freeform_slab.py, R 3,
stepover 1 mm) and the pencil of each STEP part given (R 3).

    nice python -m benchmarks.pace.command_jobs [--pencil PART.stp ...] [--rounds 2]
        [--json OUT]

Loaded machines give noisy walls: os.getloadavg() is recorded before and after.
"""

from __future__ import annotations

import argparse
import filecmp
import json
import os
import subprocess
import sys
import tempfile
import time

from benchmarks.pace.bench_pace import slab_case


def timed_command(args: list[str], folder: str, tag: str) -> tuple[float, list[str]]:
    """(wall s, output paths) of ``cadcnc ARGS -o tag.json -o tag.ngc``."""
    outs = [os.path.join(folder, f"{tag}{s}") for s in (".json", ".ngc")]
    cmd = [sys.executable, "-m", "cadcnc.cli", *args, "-q"] + \
        [w for o in outs for w in ("-o", o)]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env={**os.environ, "CADCNC_JOBS": ""})
    return time.perf_counter() - t0, outs


def measure(name: str, args: list[str], folder: str, rounds: int) -> dict:
    """Both job counts, interleaved; the fastest run of each and their ratio."""
    walls: dict[int, list[float]] = {1: [], 2: []}
    first: list[str] | None = None
    same = True
    load = os.getloadavg()
    for r in range(rounds):
        for jobs in (1, 2):
            wall, outs = timed_command([*args, "--jobs", str(jobs)], folder, f"{jobs}_{r}")
            walls[jobs].append(wall)
            first = first or outs
            same &= all(filecmp.cmp(a, b, shallow=False) for a, b in zip(first, outs))
            print(f"  {name} --jobs {jobs}: {wall:.1f} s", flush=True)
    best = {j: min(w) for j, w in walls.items()}
    return {"case": name, "walls_s": walls, "best_s": best, "speedup_2": best[1] / best[2],
            "same_bytes": same, "load_before": load, "load_after": os.getloadavg()}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pencil", nargs="*", default=[], metavar="PART.stp")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--no-slab", action="store_true")
    ap.add_argument("--json", metavar="OUT")
    args = ap.parse_args(argv)
    results = []
    with tempfile.TemporaryDirectory() as folder:
        cases = []
        if not args.no_slab:
            path, job = slab_case(folder)
            cases.append(("free-form slab finish R 3", [
                "finish", path, "--faces", str(job.operation.faces[0]), "--radius", "3",
                "--stepover", "1"]))
        cases += [(f"{os.path.basename(p)} pencil R 3", ["pencil", p, "--radius", "3"])
                  for p in args.pencil]
        for name, cmd in cases:
            results.append(measure(name, cmd, folder, args.rounds))
            r = results[-1]
            print(f"{name}: jobs 1 {r['best_s'][1]:.1f} s, jobs 2 {r['best_s'][2]:.1f} s = "
                  f"{r['speedup_2']:.2f}x; same bytes: {r['same_bytes']}; load "
                  f"{r['load_before']} -> {r['load_after']}", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
