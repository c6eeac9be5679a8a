"""Measure entries through free space on the pairs of issue 23 and the entry fixtures.

    nice .venv/bin/python -m benchmarks.entries.pairs [--radius 2] [--only NAME] [--json OUT]

Per pair: ``cadcnc path PART --faces I J --radius R -o OUT.json`` (its exit code, time and
first message line); the judge's ball positions (``coverage_judge.judge_pair``, every
0.2 mm of the pair's concave edges) where the ball and a 10 R shank fit (verdicts
``feasible`` and ``unreachable``: with or without a clear plunge from above); how many the
written cuts cover (within 5 µm); for the uncovered ones (at most SAMPLE, evenly spread),
whether any entry reaches them by the independent OCCT check (``sweeps.entries_at``: a
plunge, or a horizontal approach along +-X, +-Y), and the same at the point a skipped
stretch names (with the face OCCT finds in the plunge's way); and every link move of the written program swept with the ball
and a 10 R shank (``sweeps.links_check``). Set COVERAGE_JUDGE_CACHE to a folder to judge a
part once. Lengths mm.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.coverage.coverage_judge import covered, judge_pair_cached
from cadcnc.testing.coverage_oracle import Oracle, read_shape
from cadcnc.testing.tool_sweeps import entries_at, entry_exists, links_check

ROOT = Path(__file__).resolve().parents[2]
PARTS = ROOT.parent / "shared" / "parts"
FIXTURES = ROOT / "fixtures"
SAFE_MARGIN = 10.0  # mm above the part's top: cadcnc's default link height
SAMPLE = 12  # uncovered positions checked per pair for an entry (evenly spread)
PAIRS = [(PARTS / "bm2_ec_exhaust-A.stp", f) for f in
         ((13, 15), (13, 17), (13, 18), (13, 19), (15, 20), (17, 20))] + [
    (PARTS / "r0901_ec.stp", (3, 220))]


def fixture_pairs() -> list:
    facts = json.loads((FIXTURES / "entry_fixtures.json").read_text())
    return [(FIXTURES / f["file"], tuple(sorted((f["floor"], f["wall"]))))
            for f in facts.values()]


def run_path(step: Path, faces, radius: float, out: str) -> dict:
    t0 = time.perf_counter()
    cmd = [sys.executable, "-m", "cadcnc.cli", "path", str(step), "--faces",
           *map(str, faces), "--radius", f"{radius:g}", "-o", out]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    err = [line for line in res.stderr.splitlines() if not re.match(r"cadcnc: path: \S+ ",
                                                                    line) or "refused" in line]
    return {"code": res.returncode, "seconds": round(time.perf_counter() - t0, 1),
            "message": (err[0] if err else "")[:400], "summary": res.stdout}


def measure(step: Path, faces, radius: float, sample: int = SAMPLE) -> dict:
    rec = {"part": step.name, "faces": list(faces), "radius": radius}
    o = Oracle(read_shape(str(step)))
    offset, shank = radius, 10.0 * radius
    z_safe = float(o.boxes[:, 5].max()) + SAFE_MARGIN
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "p.json")
        rec.update(run_path(step, faces, radius, out))
        program = json.loads(Path(out).read_text()) if os.path.exists(out) else None
    judged = judge_pair_cached(str(step), o, tuple(faces), radius)
    fit = [p for e in judged["edges"] for p in e["feasible"] + e["unreachable"]]
    rec["fit"] = len(fit)
    rec["from_above"] = sum(len(e["feasible"]) for e in judged["edges"])
    lines = [np.asarray(s["points"], float) for s in (program or {}).get("segments", [])
             if s["kind"] == "cut"]
    hit = covered(fit, lines)
    rec["covered"] = int(hit.sum())
    missed = [p for p, h in zip(fit, hit) if not h]
    pick = np.unique(np.linspace(0, len(missed) - 1, min(sample, len(missed))).round()
                     .astype(int)) if missed else []
    reach = [entries_at(o, missed[k], offset, shank, z_safe) for k in pick]
    rec["uncovered_checked"] = len(reach)
    rec["uncovered_with_entry"] = sum(entry_exists(r, offset) for r in reach)
    rec["uncovered_blocked_by"] = sorted({n for r in reach for _, n in r.values() if n})
    named = re.search(r"unreachable: .*?\(([-\d.]+), ([-\d.]+), ([-\d.]+)\): (?:ball|shank) "
                      r"touches face (\d+)", rec["message"])
    if named:   # the point and face the skip names, checked independently
        p = np.array([float(x) for x in named.groups()[:3]])
        ways = entries_at(o, p, offset, shank, z_safe)
        rec["named"] = {"point": p.tolist(), "face": int(named.group(4)),
                        "entry_exists": entry_exists(ways, offset),
                        "plunge_face": ways["plunge"][1],
                        "plunge_mm_nearer": offset - ways["plunge"][0]}
    if program is not None:
        rec["links"] = links_check(o, program, offset, shank)
        rec["skipped"] = [f"{s['reason']}: {s['detail']}"[:300] for s in program["skipped"]]
        rec["notes"] = program["notes"]
    return rec


def table(records: list[dict]) -> str:
    rows = ["| part | faces | exit | s | ball + 10 R shank fit | of them plunge-clear | "
            "covered | uncovered: checked / with an entry | links: moves, worst mm nearer "
            "than R' (face) |", "|---|---|---|---|---|---|---|---|---|"]
    for r in records:
        ln = r.get("links")
        links = "-" if ln is None else f"{ln['moves']}, {ln['worst_mm']:.2g} ({ln['face']})"
        rows.append(f"| {r['part']} | {r['faces'][0]}/{r['faces'][1]} | {r['code']} | "
                    f"{r['seconds']} | {r['fit']} | {r['from_above']} | {r['covered']} | "
                    f"{r['uncovered_checked']} / {r['uncovered_with_entry']} | {links} |")
    return "\n".join(rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--radius", type=float, default=2.0)
    ap.add_argument("--only", help="parts whose name contains this")
    ap.add_argument("--fixtures", action="store_true", help="the entry fixtures too")
    ap.add_argument("--json", help="write the records here")
    ap.add_argument("--sample", type=int, default=SAMPLE,
                    help=f"uncovered positions checked per pair (default {SAMPLE})")
    args = ap.parse_args(argv)
    cases = PAIRS + (fixture_pairs() if args.fixtures else [])
    if args.only:
        cases = [c for c in cases if args.only in c[0].name]
    records = []
    for step, faces in cases:
        rec = measure(step, faces, args.radius, args.sample)
        rec["load"] = [round(x, 2) for x in os.getloadavg()]
        records.append(rec)
        print(json.dumps({k: v for k, v in rec.items() if k != "summary"}), flush=True)
    print(table(records))
    if args.json:
        Path(args.json).write_text(json.dumps(records, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
