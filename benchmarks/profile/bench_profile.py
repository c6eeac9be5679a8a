"""``python -m benchmarks profile [CASE...] [--base DIR] [--rounds N] [--json OUT]``: where a
command's CPU time goes, stage by stage, and the OCCT distance calls (count, time, the
calls over 20 ms), each command in a fresh process at ``--jobs 1`` (:mod:`.child`).

Cases (``--part`` and ``--radius`` change a case's part and ball radius):

- ``corner``: ``cadcnc path`` on the closed corner of an offset B-spline face and a
  cylinder: fixtures/bspline_boss.step offset outward by 1 mm (OCCT's
  ``BRepOffsetAPI_MakeOffsetShape``: its B-spline faces become offset surfaces), faces
  4 and 5, R 2;
- ``pencil``: ``cadcnc pencil`` on a real part with B-spline faces and edges
  (``bug32596_abc_0_13.step`` of OCCT's test data, ``data/step/``, 99 faces), R 3;
- ``setups``: ``cadcnc pencil --setups auto`` on the same part, R 3 (six candidate axes).

``--base DIR``: a checkout of the previous code (``git worktree add DIR COMMIT``); every
case is then run alternately with it and with this tree, ``--rounds`` times each, and
both are printed (the least of the rounds). A fresh checkout compiles the kernel on its
first run (about 40 s of "stepping"): run it once before, or take two rounds. CPU seconds
(``time.process_time``), so other work on the machine changes them less than wall time.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PARTS = ROOT.parent / "shared" / "parts"
CASES = {   # name: (command, default part, extra options, radius)
    "corner": ("path", "offset_boss", ["--faces", "4", "5"], "2"),
    "pencil": ("pencil", str(PARTS / "bug32596_abc_0_13.step"), [], "3"),
    "setups": ("pencil", str(PARTS / "bug32596_abc_0_13.step"), ["--setups", "auto"], "3"),
}
OFFSET_MM = 1.0


def offset_boss(folder: Path) -> str:
    """fixtures/bspline_boss.step offset outward by OFFSET_MM (faces 2 and 4: offset
    surfaces of its B-splines), written to ``folder``; its path."""
    from OCP.BRepOffset import BRepOffset_Skin
    from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffsetShape
    from OCP.GeomAbs import GeomAbs_Intersection
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    from cadcnc.geometry.part import load_step

    out = folder / "offset_boss.step"
    if not out.exists():
        maker = BRepOffsetAPI_MakeOffsetShape()
        maker.PerformByJoin(load_step(ROOT / "fixtures" / "bspline_boss.step").shape,
                            OFFSET_MM, 1e-6, BRepOffset_Skin, False, False,
                            GeomAbs_Intersection)
        writer = STEPControl_Writer()
        sys.stdout.flush()
        saved = os.dup(1)
        os.dup2(os.open(os.devnull, os.O_WRONLY), 1)   # OCCT's writer prints its statistics
        try:
            writer.Transfer(maker.Shape(), STEPControl_AsIs)
            writer.Write(str(out))
        finally:
            os.dup2(saved, 1)
            os.close(saved)
    return str(out)


def argv_of(case: str, folder: Path, part: str | None, radius: str | None) -> list[str]:
    command, default, extra, r = CASES[case]
    part = part or default
    if part == "offset_boss":
        part = offset_boss(folder)
    out = folder / f"{case}.json"
    return [command, part, *extra, "--radius", radius or r, "--jobs", "1", "-q",
            "-o", str(out)]


def run_once(argv: list[str], folder: Path, tree: str | None) -> dict:
    out = folder / "report.json"
    cmd = [sys.executable, "-m", "benchmarks.profile.child", str(out)]
    if tree:
        cmd += ["--tree", tree]
    subprocess.run(cmd + ["--", *argv], cwd=ROOT, check=True,
                   env=dict(os.environ, PYTHONPATH=str(ROOT)))
    return json.loads(out.read_text())


def table(name: str, runs: dict[str, list[dict]]) -> list[str]:
    """Lines: a stage per row, a column per code (the least of its rounds)."""
    labels = list(runs)
    best = {k: min(v, key=lambda d: d["cpu"]) for k, v in runs.items()}
    lines = [f"## {name}: {' '.join(best[labels[-1]]['argv'])}", "",
             "| | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]

    def row(title, values):
        lines.append(f"| {title} | " + " | ".join(values) + " |")

    row("CPU, whole command (s)", [f"**{best[k]['cpu']:.2f}** ("
                                   + ", ".join(f"{d['cpu']:.1f}" for d in runs[k]) + ")"
                                   for k in labels])
    row("exit code", [str(best[k]["code"]) for k in labels])
    row("imports", [f"{best[k]['imports']:.2f}" for k in labels])
    stages = [s for s in best[labels[-1]]["stages"]] + [
        s for k in labels for s in best[k]["stages"] if s not in best[labels[-1]]["stages"]]
    for s in dict.fromkeys(stages):
        row(s, [("{:.2f} ({} calls)".format(*best[k]["stages"][s])
                 if s in best[k]["stages"] else "-") for k in labels])
    where = dict.fromkeys(w for k in labels for w in best[k]["occt"])
    for w in where:
        row(f"OCCT {w}", [("{} calls, {:.2f} s".format(*best[k]["occt"][w])
                           if w in best[k]["occt"] else "-") for k in labels])
    row("OCCT calls over 20 ms", [f"{best[k]['slow_count']}, {best[k]['slow_seconds']:.2f} s"
                                  for k in labels])
    for k in labels:
        for dt, where, what in best[k]["slow"][:5]:
            lines.append(f"|   {k}: {dt * 1e3:.0f} ms | {where}: {what} |"
                         + " |" * (len(labels) - 1))
    return lines + [""]


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks profile",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("cases", nargs="*", metavar="CASE",
                    help=f"of {', '.join(CASES)} (default: all)")
    ap.add_argument("--part", help="the case's part instead of its default")
    ap.add_argument("--radius", help="the case's ball radius, mm")
    ap.add_argument("--base", metavar="DIR", help="a checkout of the previous code")
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--json", metavar="OUT", help="every run's report")
    args = ap.parse_args(argv)
    trees = {"before": str(Path(args.base).resolve())} if args.base else {}
    trees["now"] = None
    everything, lines = {}, []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for case in args.cases or list(CASES):
            if case not in CASES:
                ap.error(f"unknown case {case!r}")
            cmd = argv_of(case, folder, args.part, args.radius)
            runs: dict[str, list] = {k: [] for k in trees}
            for _ in range(args.rounds):     # alternately: before, now, before, now ...
                for label, tree in trees.items():
                    runs[label].append(run_once(cmd, folder, tree))
                    print(f"{case} {label}: {runs[label][-1]['cpu']:.1f} s CPU",
                          file=sys.stderr)
            everything[case] = runs
            lines += table(case, runs)
    print("\n".join(lines))
    if args.json:
        Path(args.json).write_text(json.dumps(everything, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
