"""Coverage of ``cadcnc pencil PART --setups auto`` against the judge, per principal axis.

For each part: the part is turned into each of the six principal setups (the library's
rigid turn, :mod:`cadcnc.geometry.setup`) and the independent judge
(``benchmarks/coverage/coverage_oracle.py``) decides, on the turned shape, which ball
positions along every concave edge (0.2 mm apart) are feasible with the shank along +Z
there, i.e. along that axis ("feasible as today"; positions no straight plunge reaches
are ``unreachable`` and left out, as in pencil_coverage). Positions are mapped back to
part coordinates; "feasible from at least one axis" is their union. Then ``cadcnc pencil
PART --setups auto --radius R -o P.json -o P.ngc`` runs as a subprocess (as a user runs
it), and a position is covered when it lies within 5 um of a cut of any setup's program
(JSON, part coordinates). Each written cut is judged (silent-bad: R' +- 1 um from its two
faces, no face nearer than R' - 1 um), and each G-code is read by LinuxCNC's rs274 and
mapped back through the setup it records (largest distance to the JSON's moves).

    nice .venv/bin/python -m benchmarks.setups.setup_coverage PARTS --radius 3 \\
        --max-pairs 40 --json benchmarks/setups/setups_R3.json

PARTS: a folder of STEP parts, e.g. the public parts of OCCT's test data
(Open-Cascade-SAS/OCCT, ``data/step/``).

``--table JSON`` prints the table of an earlier run (docs/setups.md).
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.coverage.coverage_judge import covered, judge_pair
from benchmarks.coverage.coverage_paths import cadcnc_command, classify, distance_to_polylines
from benchmarks.coverage.pair_coverage import judge_path, spread
from benchmarks.coverage.pencil_coverage import MOVE_RE
from cadcnc.testing.coverage_oracle import Oracle

AXES = ("+Z", "-Z", "+X", "-X", "+Y", "-Y")


def feasible_by_axis(step: str, radius: float, max_pairs: int | None) -> dict:
    """{axis: {key: point (3,) part coordinates}} of the judge's feasible positions, key =
    (faces, rounded point); and the pairs judged."""
    import cadcnc
    from cadcnc.geometry.setup import setup_in, setup_part

    part = cadcnc.load_step(step)
    out, pairs = {}, None
    for name in AXES:
        job = cadcnc.Job(cadcnc.Tool(radius), 1500, 0.004, cadcnc.Pencil(), axis=name)
        sp = setup_part(part, job)
        setup = setup_in(sp)
        o = Oracle(sp.given_shape)
        if pairs is None:
            pairs = spread(sorted({e.faces for e in o.concave_edges()}), max_pairs)
        found = {}
        for faces in pairs:
            for e in judge_pair(o, faces, radius)["edges"]:
                pts = np.asarray(e["feasible"], float).reshape(-1, 3)
                if setup is not None and len(pts):
                    pts = setup.to_part(pts)
                for p in pts:
                    found[(tuple(faces), tuple(np.round(p, 4)))] = p
        out[name] = found
        print(f"setup_coverage: {Path(step).name} {name}: {len(found)} feasible",
              file=sys.stderr, flush=True)
    return {"feasible": out, "pairs": pairs or []}


def rs274_back(ngc: str, data: dict) -> dict:
    """rs274 on a setup's G-code; its points mapped back to part coordinates through the
    recorded setup; the largest distance (mm) to the JSON's moves."""
    canon = ngc + ".canon"
    proc = subprocess.run(["rs274", "-g", ngc, canon], capture_output=True, text=True,
                          timeout=600)
    if proc.returncode != 0 or not os.path.exists(canon):
        return {"code": proc.returncode, "error": proc.stderr[-300:]}
    with open(canon) as fh:
        got = np.array([[float(v) for v in m.group(1).split(",")[:3]]
                        for m in MOVE_RE.finditer(fh.read())])[1:]
    s = data.get("setup")
    if s is not None and len(got):
        got = got @ np.asarray(s["rotation"]) + np.asarray(s["origin"])
    moves = np.vstack([np.asarray(g["points"], float).reshape(-1, 3)
                       for g in data["segments"]])
    far = float(distance_to_polylines(got, [moves]).max()) if len(got) else 0.0
    return {"code": 0, "points": len(got), "max_mm": far}


def run_setups(step: str, radius: float, timeout: float, tmp: str) -> dict:
    """``cadcnc pencil --setups auto``: exit, outcome, message, summary, seconds, programs."""
    cmd = [*cadcnc_command(), "pencil", step, "--radius", repr(radius), "--setups", "auto",
           "-o", os.path.join(tmp, "P.json"), "-o", os.path.join(tmp, "P.ngc")]
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        code, stdout, stderr = proc.returncode, proc.stdout, proc.stderr
    except subprocess.TimeoutExpired:
        code, stdout, stderr = None, "", f"timeout after {timeout} s"
    programs = {}
    for f in sorted(glob.glob(os.path.join(tmp, "P*.json"))):
        tag = Path(f).stem[1:]
        with open(f) as fh:
            data = json.load(fh)
        programs[tag] = {"data": data, "rs274": rs274_back(f[:-5] + ".ngc", data)}
    lines = [x for x in stderr.strip().splitlines() if "gouge check" not in x]
    return {"code": code, "outcome": classify(code, stderr), "message": " ".join(
        lines[-2:])[:2000], "summary": stdout.strip(), "seconds": round(
        time.perf_counter() - t0, 1), "programs": programs}


def measure(step: Path, radius: float, args) -> dict:
    t0 = time.perf_counter()
    judged = feasible_by_axis(str(step), radius, args.max_pairs)
    t_judge = time.perf_counter() - t0
    with tempfile.TemporaryDirectory(prefix="cadcnc-setups-") as tmp:
        run = run_setups(str(step), radius, args.timeout, tmp)
    programs = run.pop("programs")
    lines = {tag: [np.asarray(s["points"], float).reshape(-1, 3)
                   for s in p["data"]["segments"] if s["kind"] == "cut"]
             for tag, p in programs.items()}
    union = {}
    for found in judged["feasible"].values():
        union.update(found)
    keys = list(union)
    every = [line for ls in lines.values() for line in ls]
    hit = covered([union[k] for k in keys], every) if keys else np.zeros(0, bool)
    hit_of = dict(zip(keys, hit))
    per_axis = {a: {"feasible": len(f), "covered": int(sum(hit_of[k] for k in f))}
                for a, f in judged["feasible"].items()}
    pairs = set(map(tuple, judged["pairs"]))
    from benchmarks.coverage.pair_coverage import oracle_for

    o = oracle_for(str(step))
    bad, checked = 0, 0
    for tag, p in programs.items():
        for s, line in zip([s for s in p["data"]["segments"] if s["kind"] == "cut"],
                           lines[tag]):
            if tuple(sorted(s["faces"])) in pairs and None not in s["faces"]:
                b = judge_path(o, tuple(s["faces"]), [line], radius, args.check_points)
                bad += b["bad"]
                checked += b["checked"]
    rec = {"part": step.name, "radius": radius, "pairs_judged": len(pairs),
           "feasible_any": len(keys), "covered": int(hit.sum()), "per_axis": per_axis,
           "setups": list(programs), "silent_bad": bad, "checked": checked,
           "rs274": {t: p["rs274"] for t, p in programs.items()},
           "judge_seconds": round(t_judge, 1), "run": run,
           "load": os.getloadavg()}
    return rec


def table(records: list[dict]) -> str:
    rows = ["| part | pairs judged | feasible from any axis | " + " | ".join(AXES) +
            " | setups chosen | covered | % | silent-bad | rs274 max mm | exit | s |",
            "|" + "---|" * (10 + len(AXES))]
    for r in records:
        f, c = r["feasible_any"], r["covered"]
        rs = [v.get("max_mm") for v in r["rs274"].values()]
        rs_text = "-" if not rs else ("failed" if None in rs else f"{max(rs):.1e}")
        rows.append(
            f"| {r['part']} | {r['pairs_judged']} | {f} | " + " | ".join(
                f"{r['per_axis'][a]['feasible']}" for a in AXES) +
            f" | {' '.join(r['setups']) or '-'} | {c} | "
            f"{100.0 * c / f:.1f} | " if f else f"| {r['part']} | {r['pairs_judged']} | 0 | "
            + " | ".join("0" for _ in AXES) + f" | {' '.join(r['setups']) or '-'} | 0 | - | ")
        rows[-1] += (f"{r['silent_bad']} | {rs_text} | {r['run']['code']} | "
                     f"{r['run']['seconds']} |")
    tot_f = sum(r["feasible_any"] for r in records)
    tot_c = sum(r["covered"] for r in records)
    rows.append(f"| all | | {tot_f} | " + " | ".join(
        str(sum(r["per_axis"][a]["feasible"] for r in records)) for a in AXES) +
        f" | | {tot_c} | {100.0 * tot_c / max(tot_f, 1):.1f} | "
        f"{sum(r['silent_bad'] for r in records)} | | | |")
    rows.append("")
    for r in records:
        if r["run"]["code"] != 0:
            rows.append(f"- {r['part']}: exit {r['run']['code']} ({r['run']['outcome']}): "
                        f"{r['run']['message'][:300]}")
        m = re.search(r"^setups .*$", r["run"]["summary"], re.M)
        if m:
            rows.append(f"- {r['part']}: {m.group(0)}")
    return "\n".join(rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs="*")
    ap.add_argument("--radius", type=float, default=3.0)
    ap.add_argument("--max-pairs", type=int, default=40)
    ap.add_argument("--timeout", type=float, default=3600.0)
    ap.add_argument("--check-points", type=int, default=30)
    ap.add_argument("--json")
    ap.add_argument("--table", nargs="+")
    args = ap.parse_args(argv)
    if args.table:
        print(table([r for p in args.table for r in json.loads(Path(p).read_text())]))
        return 0
    files = []
    for p in map(Path, args.paths):
        files += sorted(x for x in p.iterdir() if x.suffix.lower() in (".step", ".stp")) \
            if p.is_dir() else [p]
    records = []
    for f in files:
        try:
            rec = measure(f, args.radius, args)
        except Exception as exc:  # noqa: BLE001 - a benchmark records a crash and goes on
            rec = {"part": f.name, "crash": f"{type(exc).__name__}: {exc}"}
            print(f"setup_coverage: {f.name}: CRASH {rec['crash']}", file=sys.stderr)
            if args.json:
                Path(args.json + ".crashes").open("a").write(json.dumps(rec) + "\n")
            continue
        records.append(rec)
        print(f"setup_coverage: {f.name}: {rec['covered']}/{rec['feasible_any']} setups "
              f"{rec['setups']} exit {rec['run']['code']} {rec['run']['seconds']} s",
              file=sys.stderr, flush=True)
        if args.json:
            Path(args.json).write_text(json.dumps(records, indent=1, default=str))
    print(table(records))
    return 0


if __name__ == "__main__":
    sys.exit(main())
