"""The gate on a free-form slab (issue 37, item 6): ``cadcnc finish`` on
fixtures/finish_wave.step (R 3, stepover 1 mm, about 57 000 centres).

For this checkout and, with ``--base DIR``, the previous code's checkout (a tree with its
own ``cadcnc/``, e.g. ``git archive REV cadcnc | tar -x -C DIR``), alternated round by
round:

- the computation and the gate at one process, in CPU seconds of one process
  (benchmarks/pace/gate_wave_child.py), and their ratio (target: gate <= 0.5x);
- the whole command at ``--jobs 1`` and ``--jobs 2`` (a new process each: wall seconds,
  and the CPU seconds of the process and its workers), and the speed-up (target 1.5x on
  an idle machine);
- whether both checkouts give the same verdicts, depths and G-code.

    nice python -m benchmarks.pace.gate_wave [--base DIR] [--rounds 2] [--json OUT]

Each tree's modules are compiled to bytecode first (``compileall``), as Python caches
them on a user's machine after the first run: this environment sets
``PYTHONDONTWRITEBYTECODE=1``, under which every command compiled cadcnc's modules afresh,
about 0.3 s of its serial start (``--source`` measures that way).

The machine is shared: os.getloadavg() is printed with each round; compare ratios.
"""

from __future__ import annotations

import argparse
import compileall
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "fixtures" / "finish_wave.step"
FACE = json.loads((ROOT / "fixtures" / "finish_fixtures.json").read_text())["wave"]["top"]
CHILD = Path(__file__).with_name("gate_wave_child.py")


def _children_cpu() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def split(tree: str) -> dict:
    """The child's computation and gate CPU seconds, verdicts and G-code digest."""
    out = subprocess.run([sys.executable, str(CHILD), str(FIXTURE), str(FACE)], cwd=tree,
                         env={**os.environ, "PYTHONPATH": tree}, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def command(tree: str, jobs: int, folder: str) -> dict:
    """The whole ``cadcnc finish`` at ``jobs``: wall and CPU seconds (workers included)."""
    outs = [os.path.join(folder, f"w{jobs}{s}") for s in (".json", ".ngc")]
    cmd = [sys.executable, "-m", "cadcnc.cli", "finish", str(FIXTURE), "--faces", str(FACE),
           "--radius", "3", "--stepover", "1", "--jobs", str(jobs), "-q"] + \
        [w for o in outs for w in ("-o", o)]
    c0, t0 = _children_cpu(), time.perf_counter()
    # run in the temporary folder: ``-m`` puts the working directory first on the path
    subprocess.run(cmd, check=True, cwd=folder,
                   env={**os.environ, "PYTHONPATH": tree, "CADCNC_JOBS": ""})
    return {"wall_s": time.perf_counter() - t0, "cpu_s": _children_cpu() - c0}


def one_round(trees: dict[str, str], folder: str) -> dict:
    """Every measurement of every tree, the trees alternated within each kind."""
    out: dict = {name: {"load": os.getloadavg()} for name in trees}
    for name, tree in trees.items():
        out[name]["split"] = split(tree)
    for jobs in (1, 2):
        for name, tree in trees.items():
            out[name][f"jobs{jobs}"] = command(tree, jobs, folder)
    return out


def report(name: str, r: dict) -> str:
    s, j1, j2 = r["split"], r["jobs1"], r["jobs2"]
    return (f"  {name:8s} {s['points']} centres: computed {s['compute_cpu_s']:.2f} s, gated "
            f"{s['gate_cpu_s']:.2f} s CPU = {s['gate_cpu_s'] / s['compute_cpu_s']:.2f}x; "
            f"command jobs 1 {j1['wall_s']:.1f} s ({j1['cpu_s']:.1f} CPU), jobs 2 "
            f"{j2['wall_s']:.1f} s ({j2['cpu_s']:.1f} CPU) = {j1['wall_s'] / j2['wall_s']:.2f}x"
            f"; load {', '.join(f'{x:.1f}' for x in r['load'])}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", metavar="DIR", help="the previous code's checkout")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--json", metavar="OUT")
    ap.add_argument("--source", action="store_true",
                    help="leave the modules uncompiled (every command compiles them)")
    args = ap.parse_args(argv)
    trees = {"now": str(ROOT)}
    if args.base:
        trees = {"previous": os.path.abspath(args.base), **trees}
    if not args.source:
        for tree in trees.values():
            compileall.compile_dir(os.path.join(tree, "cadcnc"), quiet=1)
    rounds = []
    with tempfile.TemporaryDirectory() as folder:
        for k in range(args.rounds):
            rounds.append(one_round(trees, folder))
            print(f"round {k + 1}:", flush=True)
            for name in trees:
                print(report(name, rounds[-1][name]), flush=True)
            if args.base:
                a, b = rounds[-1]["previous"]["split"], rounds[-1]["now"]["split"]
                print(f"  same verdicts: {a['verdicts'] == b['verdicts']}; same depths: "
                      f"{a['depths'] == b['depths']}; same G-code: "
                      f"{a['gcode_sha256'] == b['gcode_sha256']}", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rounds, indent=1))


if __name__ == "__main__":
    main()
