"""Coverage of the whole part by ``cadcnc pencil`` (issue 12), as the judge measures it.

For each part and radius: the independent judge (``coverage_oracle.py``) samples every
concave shared edge of the part every 0.2 mm (no cap) and decides which ball positions
are feasible; ``cadcnc pencil PART --radius R --feed 1500 --period 4ms -o P.json -o
P.ngc`` runs as a subprocess (what a user, and the judge, run); a feasible position is
covered when it lies within 5 um of any cut of the program. Positions the spec calls
feasible but no plunge from above reaches (a sealed void, an overhang higher than the
shank: verdict ``unreachable``) are counted apart and left out of coverage (issue 12).
Written cuts are judged too (silent-bad): every checked point R' +- 1 um from its two
faces, and no face nearer than R' - 1 um.

    python -m benchmarks.coverage.pencil_coverage [PATH ...] [--fixtures] --radius 3 [--radius 2]
        [--json OUT] [--timeout 3600] [--check-points 30]

PATH: STEP files or folders of them. Prints, per part and radius: covered / feasible,
missed stretches (runs of uncovered positions), unreachable positions, the program's
skipped corners by reason, exit code and message, silent-bad, the CLI's time breakdown.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks import ROOT
from benchmarks.coverage.coverage_judge import covered, judge_pair_cached, missed_runs
from benchmarks.coverage.coverage_paths import cadcnc_command, classify, distance_to_polylines
from benchmarks.coverage.pair_coverage import (
    judge_path,
    oracle_for,
    pairs_of,
    spread,
    unique_corrections,
)


def _children_cpu() -> float:
    """User + system CPU seconds of this process's finished children."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def run_pencil(step: str, radius: float, timeout: float, tmp: str) -> dict:
    """One ``cadcnc pencil`` run writing P.json and P.ngc: exit code, outcome, message,
    stdout summary, seconds, and the program JSON (None when nothing was written)."""
    out = os.path.join(tmp, "P.json")
    cmd = [*cadcnc_command(), "pencil", step, "--radius", repr(radius), "--feed", "1500",
           "--period", "4ms", "-o", out, "-o", os.path.join(tmp, "P.ngc")]
    t0 = time.perf_counter()
    cpu0 = _children_cpu()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        code, stdout, stderr = proc.returncode, proc.stdout, proc.stderr
    except subprocess.TimeoutExpired:
        code, stdout, stderr = None, "", f"timeout after {timeout} s"
    seconds = time.perf_counter() - t0
    cpu = _children_cpu() - cpu0
    data, rs = None, None
    if code == 0 and os.path.exists(out):
        with open(out) as fh:
            data = json.load(fh)
        rs = rs274_check(os.path.join(tmp, "P.ngc"), data)
    lines = [x for x in stderr.strip().splitlines() if "pencil: corner " not in x]
    return {"code": code, "outcome": classify(code, stderr),
            "message": " ".join(lines[-1:])[:3000], "summary": stdout.strip(),
            "seconds": round(seconds, 1), "cpu_seconds": round(cpu, 1), "program": data,
            "rs274": rs}


MOVE_RE = re.compile(r"STRAIGHT_(?:FEED|TRAVERSE)\(([^)]*)\)")


def rs274_check(ngc: str, program: dict) -> dict:
    """LinuxCNC's rs274 on the G-code: its exit code, the STRAIGHT_FEED / TRAVERSE points
    it reads (the first, the machine's home, left out) and their largest distance (mm)
    to the program's moves (every segment's points in order, as one polyline)."""
    canon = ngc + ".canon"
    try:
        proc = subprocess.run(["rs274", "-g", ngc, canon], capture_output=True, text=True,
                              timeout=600)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}
    if proc.returncode != 0 or not os.path.exists(canon):
        return {"code": proc.returncode, "error": proc.stderr[-300:]}
    with open(canon) as fh:
        got = np.array([[float(v) for v in m.group(1).split(",")[:3]]
                        for m in MOVE_RE.finditer(fh.read())])[1:]
    moves = np.vstack([np.asarray(s["points"], float).reshape(-1, 3)
                       for s in program["segments"]])
    far = float(distance_to_polylines(got, [moves]).max()) if len(got) else 0.0
    return {"code": 0, "points": len(got), "max_mm": far}


def measure(step: Path, radius: float, args) -> dict:
    """Judge every concave edge of ``step`` at R' = radius, run pencil, compare."""
    t0 = time.perf_counter()
    rec = {"part": step.name, "radius": radius}
    with tempfile.TemporaryDirectory(prefix="cadcnc-pencil-cov-") as tmp:
        run = run_pencil(str(step), radius, args.timeout, tmp)
    prog = run.pop("program")
    rec["run"] = run
    print(f"pencil_coverage: {step.name} R {radius}: pencil exit {run['code']} in "
          f"{run['seconds']} s ({run['cpu_seconds']} s CPU); {times(run['summary'])}",
          file=sys.stderr, flush=True)
    t1 = time.perf_counter()
    pairs, problem = pairs_of(str(step))
    rec["pairs"], rec["problem"] = len(pairs), problem
    pairs = spread(pairs, args.max_pairs)
    rec["pairs_judged"] = len(pairs)
    o = oracle_for(str(step)) if pairs else None
    edges = [e for faces in pairs
             for e in judge_pair_cached(str(step), o, faces, radius)["edges"]]
    rec["judge_seconds"] = round(time.perf_counter() - t1, 1)
    cuts = [s for s in (prog or {}).get("segments", []) if s.get("kind") == "cut"]
    lines = [np.asarray(s["points"], float).reshape(-1, 3) for s in cuts]
    rec["feasible"] = sum(len(e["feasible"]) for e in edges)
    rec["unreachable"] = sum(len(e["unreachable"]) for e in edges)
    rec["covered"], rec["missed"], rec["per_edge"] = 0, [], []
    for e in edges:
        hit = covered(e["feasible"], lines)
        rec["covered"] += int(hit.sum())
        runs = missed_runs(e["feasible"], e["index"], hit)
        rec["missed"] += [dict(r, faces=e["faces"], edge=e["edge"]) for r in runs]
        rec["per_edge"].append({"faces": e["faces"], "edge": e["edge"],
                                "feasible": len(e["feasible"]), "covered": int(hit.sum()),
                                "unreachable": len(e["unreachable"]),
                                "verdicts": e["verdicts"]})
    rec["skipped"] = dict(collections.Counter(s["reason"] for s in (prog or {}).get(
        "skipped", [])))
    rec["skipped_detail"] = [f"{s['faces']} edge {s.get('edge')}: {s['reason']}: "
                             f"{s['detail']}"[:400] for s in (prog or {}).get("skipped", [])]
    if prog:
        rec["summary"] = prog.get("summary", {})
        bad = [judge_path(o, tuple(s["faces"]), [line], radius, args.check_points)
               for s, line in zip(cuts, lines) if None not in s["faces"]] if o else []
        rec["check"] = {"cuts": len(bad), "bad": sum(b["bad"] for b in bad),
                        "points": sum(b["checked"] for b in bad),
                        "off_face_mm": max((b["off_face_mm"] for b in bad), default=0.0),
                        "gouge_mm": max((b["gouge_mm"] for b in bad), default=0.0),
                        "bad_cuts": [{"faces": s["faces"], **{k: b[k] for k in (
                            "off_face_mm", "gouge_mm")}} for s, b in zip(cuts, bad) if b["bad"]],
                        "corrected": [c for b in bad for c in b["corrected"]]}
    rec["seconds"] = round(time.perf_counter() - t0, 1)
    return rec


def times(summary: str) -> str:
    """The CLI's time breakdown line, if it printed one."""
    m = re.search(r"times\s+(.*)", summary)
    return m.group(1) if m else "-"


def _pairs(r: dict) -> str:
    """Concave pairs judged, "n of N" when capped."""
    n = r.get("pairs_judged", r["pairs"])
    return str(n) if n == r["pairs"] else f"{n} of {r['pairs']}"


def _rs(r: dict) -> str:
    """rs274's reading: "ok (n points, max mm)" or what went wrong."""
    rs = r["run"].get("rs274")
    if not rs:
        return "-"
    if rs.get("code") != 0:
        return f"failed: {rs.get('error', '')[:60]}"
    return f"ok ({rs['points']} pts, {rs['max_mm']:.1e} mm)"


def table(records: list[dict]) -> str:
    rows = ["| part | R mm | concave pairs | covered / feasible | % | missed stretches | "
            "unreachable from +Z | cuts | cut mm | link mm | skipped by reason | exit | "
            "silent-bad | rs274 | pencil s |", "|" + "---|" * 15]
    for r in records:
        f, c = r["feasible"], r["covered"]
        s = r.get("summary", {})
        rows.append(
            f"| {r['part']} | {r['radius']} | {_pairs(r)} | {c} / {f} | "
            f"{100.0 * c / f:.1f} | {len(r['missed'])} | {r['unreachable']} | "
            f"{s.get('cuts', '-')} | {s.get('cut_length_mm', 0):.1f} | "
            f"{s.get('link_length_mm', 0):.1f} | "
            f"{', '.join(f'{k} {v}' for k, v in sorted(r['skipped'].items())) or '-'} | "
            f"{r['run']['code']} | {r.get('check', {}).get('bad', '-')} | "
            f"{_rs(r)} | {r['run']['seconds']} |" if f else
            f"| {r['part']} | {r['radius']} | {_pairs(r)} | 0 / 0 | - | 0 | "
            f"{r['unreachable']} | {s.get('cuts', '-')} | - | - | "
            f"{', '.join(f'{k} {v}' for k, v in sorted(r['skipped'].items())) or '-'} | "
            f"{r['run']['code']} | - | {_rs(r)} | {r['run']['seconds']} |")
    rows.append("")
    for r in records:
        if r["run"]["code"] != 0:
            rows.append(f"- {r['part']} R {r['radius']}: exit {r['run']['code']} "
                        f"({r['run']['outcome']}): {r['run']['message'][:400]}")
        for m in r["missed"][:5]:
            rows.append(f"- {r['part']} R {r['radius']}: missed faces {m['faces']} edge "
                        f"{m['edge']}: {m['n']} positions {m['from']} .. {m['to']}")
        check = r.get("check", {})
        for b in check.get("bad_cuts", []):
            rows.append(f"- {r['part']} R {r['radius']}: silent-bad cut faces {b['faces']}: "
                        f"off its faces by {b['off_face_mm']:.2e} mm, gouge "
                        f"{b['gouge_mm']:.2e} mm")
        for c in unique_corrections(check.get("corrected", [])):
            rows.append(f"- {r['part']} R {r['radius']}: face {c['face']} at "
                        f"{[round(x, 4) for x in c['p']]}: BRepExtrema {c['brepextrema']:.4f}"
                        f" mm, foot on the face (FClass2d) {c['foot']:.4f} mm: the foot counts")
        if times(r["run"].get("summary", "")) != "-":
            rows.append(f"- {r['part']} R {r['radius']}: {times(r['run']['summary'])}")
    return "\n".join(rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs="*", help="STEP files or folders of them")
    ap.add_argument("--fixtures", action="store_true", help="fixtures/*.step as well")
    ap.add_argument("--radius", type=float, action="append", help="ball radius, mm")
    ap.add_argument("--timeout", type=float, default=3600.0, help="per pencil run, s")
    ap.add_argument("--check-points", type=int, default=30,
                    help="points judged per cut at most (silent-bad)")
    ap.add_argument("--max-pairs", type=int, default=None, help="judge at most this many "
                    "concave pairs per part, evenly spread in face order (default all; pencil "
                    "still cuts the whole part)")
    ap.add_argument("--json", help="write the records here")
    ap.add_argument("--table", nargs="+", metavar="JSON", help="print the table of earlier "
                    "--json files (merged) instead of running")
    args = ap.parse_args(argv)
    if args.table:
        records = [r for path in args.table for r in json.loads(Path(path).read_text())[
            "records"]]
        print(table(records))
        return 0
    files = sorted((ROOT / "fixtures").glob("*.step")) if args.fixtures else []
    for p in map(Path, args.paths):
        files += sorted(x for x in p.iterdir() if x.suffix.lower() in (".step", ".stp")) \
            if p.is_dir() else [p]
    records = []
    for f in files:
        for radius in args.radius or [3.0]:
            rec = measure(f, radius, args)
            records.append(rec)
            print(f"pencil_coverage: {f.name} R {radius}: {rec['covered']}/{rec['feasible']}"
                  f" (exit {rec['run']['code']}, {rec['seconds']} s)", file=sys.stderr,
                  flush=True)
            if args.json:
                with open(args.json + ".tmp", "w") as fh:
                    json.dump({"records": records}, fh, indent=1, default=float)
                os.replace(args.json + ".tmp", args.json)
    print(table(records))
    return 0


if __name__ == "__main__":
    sys.exit(main())
