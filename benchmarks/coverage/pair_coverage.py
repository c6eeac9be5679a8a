"""Coverage of cadcnc's paths over every concave pair of the fixtures and of real parts.

Issue 10's measurement (docs/notes/coverage.md): the independent judge in
``coverage_oracle.py`` samples every concave shared edge every 0.2 mm and decides which
ball positions are feasible; ``cadcnc path`` (the command line, one subprocess per run)
writes paths; a feasible position is covered when it lies within 5 um of a written cut
polyline of its pair. Written paths are judged too: a point whose distance to either of
its two faces differs from R' by more than 1 um, or that is nearer than R' - 1 um to any
face, makes the path silent-bad.

    python -m benchmarks.coverage.pair_coverage [--fixtures] [--parts DIR] --radius 2 [--radius 3]
        [--feed 1500] [--period 4ms] [--json OUT] [--workers 2] [--timeout 120]
        [--max-samples 60] [--max-pairs N]

Prints covered / feasible (with and without the shank), refusals by reason, silent-bad and
crash counts, per part and in total; progress goes to stderr.
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import multiprocessing
import os
import re
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks import ROOT
from benchmarks.coverage.coverage_judge import covered, judge_pair_cached, missed_runs
from benchmarks.coverage.coverage_paths import classify, run_faces, run_path
from cadcnc.testing.coverage_oracle import TOL, Oracle, read_shape

_ORACLES: dict[str, Oracle] = {}
SHOWN_CORRECTION = 1e-4  # mm: face_distance corrections listed (smaller: far below 1 um)


def oracle_for(step: str) -> Oracle:
    """One judge per part and worker process (reading a large part takes seconds)."""
    if step not in _ORACLES:
        _ORACLES.clear()
        _ORACLES[step] = Oracle(read_shape(step))
    return _ORACLES[step]


def pairs_of(step: str) -> tuple[list[tuple[int, int]], str | None]:
    """The pairs having at least one concave edge by the judge's classification."""
    try:
        o = oracle_for(step)
    except Exception as exc:  # noqa: BLE001 - an unreadable file is reported, not fatal
        return [], f"{type(exc).__name__}: {exc}"
    return sorted({e.faces for e in o.concave_edges()}), None


def judge_path(o: Oracle, faces, polylines, offset: float, cap: int) -> dict:
    """Silent-bad check of written cut points (at most ``cap`` evenly spread per polyline).

    ``shank_mm``: how far the shank (p to p + 10 R' z) comes nearer than R' to the part
    at the worst checked point, with its face; reported beside silent-bad (the shank
    rule is the spec's, the gouge gate does not check it). ``corrected``: distances where
    BRepExtrema's answer was replaced by one shorter by more than SHOWN_CORRECTION to a
    foot on the face (``Oracle.face_distance``), each (face, point) once."""
    worst_face, worst_gouge, checked = 0.0, 0.0, 0
    worst_shank, shank_face = 0.0, 0
    corrections = len(o.corrections)
    for line in polylines:
        idx = np.unique(np.linspace(0, len(line) - 1, min(cap, len(line))).round().astype(int))
        for p in line[idx]:
            checked += 1
            for n in faces:
                worst_face = max(worst_face, abs(o.face_distance(p, n) - offset))
            dist, _ = o.clearance(p, offset)
            if math.isfinite(dist):
                worst_gouge = max(worst_gouge, offset - dist)
            dist, face = o.shank_clearance(p, 10.0 * offset, offset)
            if math.isfinite(dist) and offset - dist > worst_shank:
                worst_shank, shank_face = offset - dist, face
    return {"checked": checked, "off_face_mm": worst_face, "gouge_mm": worst_gouge,
            "shank_mm": worst_shank, "shank_face": shank_face,
            "corrected": unique_corrections(o.corrections[corrections:]),
            "bad": worst_face > TOL or worst_gouge > TOL}


def unique_corrections(found: list[dict]) -> list[dict]:
    """The corrections above SHOWN_CORRECTION, each (face, point) once."""
    seen, out = set(), []
    for c in found:
        key = (c["face"], tuple(c["p"]))
        if c["brepextrema"] - c["foot"] > SHOWN_CORRECTION and key not in seen:
            seen.add(key)
            out.append(c)
    return out


def run_pair(task: dict) -> dict:
    """Judge one pair: sample its concave edges, run cadcnc, compare. Never raises."""
    step, faces, radius = task["step"], tuple(task["faces"]), task["radius"]
    t0 = time.perf_counter()
    rec = {"part": task["name"], "faces": list(faces), "radius": radius, "edges": [],
           "runs": [], "feasible": 0, "feasible_ball": 0, "covered": 0, "covered_ball": 0}
    try:
        o = oracle_for(step)
        offset = radius
        judged = judge_pair_cached(step, o, faces, radius, task["max_samples"])
        feasible = [p for e in judged["edges"] for p in e["feasible"]]
        ball = [p for e in judged["edges"] for p in e["ball"]]
        unreachable = [p for e in judged["edges"] for p in e["unreachable"]]
        rec["edges"] = [{k: e[k] for k in ("edge", "length_mm", "verdicts")}
                        for e in judged["edges"]]
        edges = judged["edges"]
        via = task.get("via", "cli")
        runs = [run_path(step, faces, radius, task["feed"], task["period"], task["timeout"],
                         via=via)]
        if via == "cli" and runs[0]["version"] in (None, 1):  # v1: one edge per run
            for k in range(2, len(edges) + 1):
                runs.append(run_path(step, faces, radius, task["feed"], task["period"],
                                     task["timeout"], edge=k))
        polylines = [line for r in runs for line in r["polylines"]]
        refused = polylines + [line for r in runs for line in r["refused_polylines"]]
        for name, pts, lines in (("covered", feasible, polylines),
                                 ("covered_ball", ball, polylines),
                                 ("covered_unreachable", unreachable, polylines),
                                 ("covered_ungated", feasible, refused)):
            rec[name] = int(np.count_nonzero(covered(pts, lines)))
        rec["missed"] = [dict(run, edge=e["edge"]) for e in edges for run in missed_runs(
            e["feasible"], e["index"], covered(e["feasible"], polylines))]
        rec["feasible"], rec["feasible_ball"] = len(feasible), len(ball)
        rec["unreachable"] = len(unreachable)
        if polylines:
            rec["path_check"] = judge_path(o, faces, polylines, offset, task["check_points"])
        rec["runs"] = [{k: v for k, v in r.items() if k not in ("polylines", "refused_polylines")}
                       | {"points": sum(len(x) for x in r["polylines"])} for r in runs]
    except Exception as exc:  # noqa: BLE001 - the judge's own failure is reported per pair
        rec["error"] = f"{type(exc).__name__}: {exc}"
    rec["seconds"] = round(time.perf_counter() - t0, 2)
    return rec


def spread(items: list, cap: int | None) -> list:
    """At most ``cap`` items, evenly spread and in order (all when cap is None)."""
    if cap is None or len(items) <= cap:
        return items
    return [items[i] for i in np.linspace(0, len(items) - 1, cap).round().astype(int)]


def tasks_for(args) -> tuple[list[dict], list[dict]]:
    """(per-pair tasks, per-file notes) for every requested part and radius."""
    files = []
    if args.fixtures:
        files += sorted((ROOT / "fixtures").glob("*.step"))
    if args.parts:
        where = Path(args.parts)
        files += [where] if where.is_file() else sorted(
            p for p in where.iterdir() if p.suffix.lower() in (".step", ".stp"))
    tasks, notes = [], []
    for f in files:
        pairs, problem = pairs_of(str(f))
        note = {"part": f.name, "pairs": len(pairs), "problem": problem}
        if not pairs:  # what cadcnc itself makes of a file with nothing to judge
            note["cadcnc_faces"] = run_faces(str(f), args.timeout)
        notes.append(note)
        print(f"coverage: {f.name}: {len(pairs)} concave pairs"
              + (f" ({problem})" if problem else ""), file=sys.stderr, flush=True)
        for radius in args.radius:
            for faces in spread(pairs, args.max_pairs):
                tasks.append({"step": str(f), "name": f.name, "faces": faces, "via": args.via,
                              "radius": radius, "feed": args.feed, "period": args.period,
                              "timeout": args.timeout, "max_samples": args.max_samples,
                              "check_points": args.check_points})
    return tasks, notes


EDGE_REASONS = re.compile(r"edge \d+: no feasible ball position: ([^(;]+)")


def program_notes(records: list[dict], radius: float) -> list[str]:
    """Version 2 runs: edges refused or skipped by the stretch finder, by its reason;
    cuts the gate refused, and the feasible positions they would have covered."""
    edges, gated = collections.Counter(), 0
    for r in records:
        for run in r.get("runs", []):
            text = " ".join([run.get("message", "")] + run.get("skipped", []))
            edges.update(m.strip() for m in EDGE_REASONS.findall(text))
            edges.update("cut stopped short" for k in run.get("skipped", [])
                         if "stopped short" in k)
            gated += len(run.get("gate_refused", []))
    if not edges and not gated:
        return []
    extra = sum(r.get("covered_ungated", 0) - r["covered"] for r in records)
    return [f"R {radius}: edges without a cut, by the stretch finder's reason: "
            + ", ".join(f"{k} {v}" for k, v in edges.most_common())
            + f"; cuts refused by the gate {gated} (they would have covered {extra} more)"]


def table(records: list[dict], notes: list[dict]) -> str:
    """The per-part and total figures as a Markdown table, then refusals by reason."""
    rows = ["| part | R mm | pairs | covered / feasible | % | missed stretches | unreachable "
            "from +Z: covered / all | ball only: covered / feasible | % | paths written | "
            "silent-bad | crashes | refused runs by reason |", "|" + "---|" * 13]
    reasons = collections.defaultdict(collections.Counter)
    groups = collections.defaultdict(list)
    for r in records:
        groups[(r["part"], r["radius"])].append(r)
        for run in r.get("runs", []):
            if run["outcome"] != "written":
                reasons[r["radius"]][run["outcome"]] += 1
        if "error" in r:
            reasons[r["radius"]]["judge error"] += 1
    for radius in sorted({r["radius"] for r in records}):
        groups[("**total**", radius)] = [x for x in records if x["radius"] == radius]
    for (part, radius), rs in groups.items():
        c, f = sum(r["covered"] for r in rs), sum(r["feasible"] for r in rs)
        cb, fb = sum(r["covered_ball"] for r in rs), sum(r["feasible_ball"] for r in rs)
        runs = [run for r in rs for run in r.get("runs", [])]
        written = sum(run["outcome"] == "written" for run in runs)
        bad = sum(bool(r.get("path_check", {}).get("bad")) for r in rs)
        crashes = sum(run["outcome"] in ("crash", "timeout") for run in runs)
        pct = lambda a, b: f"{100.0 * a / b:.1f}" if b else "-"  # noqa: E731
        cu, u = (sum(r.get(k, 0) for r in rs) for k in ("covered_unreachable", "unreachable"))
        missed = sum(len(r.get("missed", [])) for r in rs)
        rows.append(f"| {part} | {radius} | {len(rs)} | {c} / {f} | {pct(c, f)} | {missed} "
                    f"| {cu} / {u} | {cb} / {fb} | {pct(cb, fb)} | {written} / {len(runs)} "
                    f"| {bad} | {crashes} | {_refusals(runs)} |")
    rows.append("")
    for radius, counts in sorted(reasons.items()):
        rows.append(f"R {radius}: runs not written, by reason: "
                    + ", ".join(f"{k} {v}" for k, v in counts.most_common()))
    for radius in sorted({r["radius"] for r in records}):
        rows.extend(program_notes([r for r in records if r["radius"] == radius], radius))
    for r in records:
        for c in unique_corrections(r.get("path_check", {}).get("corrected", [])):
            rows.append(f"{r['part']} faces {r['faces']} R {r['radius']}: face {c['face']} at "
                        f"{[round(x, 4) for x in c['p']]}: BRepExtrema {c['brepextrema']:.4f}"
                        f" mm, foot on the face (FClass2d) {c['foot']:.4f} mm: the foot counts")
    for n in notes:
        if n["problem"] or not n["pairs"]:
            rows.append(f"{n['part']}: no pair judged ({n['problem'] or 'no concave edge'}); "
                        f"`cadcnc faces`: {n.get('cadcnc_faces', '-')}")
    return "\n".join(rows)


SHORT = {"no feasible position (stretch finder)": "no feasible position",
         "ball cuts the part (gouge gate)": "gate"}


def _refusals(runs: list[dict]) -> str:
    """Runs not written, by reason (short names), e.g. "no feasible position 3, gate 1"."""
    counts = collections.Counter(SHORT.get(r["outcome"], r["outcome"]) for r in runs
                                 if r["outcome"] != "written")
    return ", ".join(f"{k} {v}" for k, v in counts.most_common()) or "-"


def print_table(paths: list[str]) -> int:
    """The table of earlier runs' records (several --json files are merged), refusal
    reasons re-read from the messages."""
    data = {"records": [], "notes": []}
    for path in paths:
        with open(path) as fh:
            one = json.load(fh)
        data["records"] += one["records"]
        data["notes"] += one["notes"]
    for rec in data["records"]:
        for run in rec.get("runs", []):
            if run["outcome"] not in ("written", "crash", "timeout"):
                run["outcome"] = classify(run["code"], run["message"])
    print(table(data["records"], data["notes"]))
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fixtures", action="store_true", help="judge fixtures/*.step")
    ap.add_argument("--parts", help="a folder of STEP parts (or one STEP file) to judge "
                    "as well")
    ap.add_argument("--radius", type=float, action="append", help="ball radius, mm (repeatable)")
    ap.add_argument("--feed", type=float, default=1500.0, help="mm/min")
    ap.add_argument("--period", default="4ms")
    ap.add_argument("--timeout", type=float, default=120.0, help="per cadcnc run, s")
    ap.add_argument("--max-samples", type=int, default=None, help="samples per edge at "
                    "most (default none: every 0.2 mm; a cap widens the spacing on longer "
                    "edges)")
    ap.add_argument("--max-pairs", type=int, default=None, help="pairs per part at most, "
                    "evenly spread (default all)")
    ap.add_argument("--check-points", type=int, default=100,
                    help="written points judged per cut polyline at most (silent-bad)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--via", choices=("cli", "api"), default="cli",
                    help="cli: `cadcnc path`; api: the program pipeline (program_for_job, "
                    "gate per cut) through benchmarks/coverage/coverage_run_pair.py")
    ap.add_argument("--json", help="write per-pair records here")
    ap.add_argument("--table", metavar="JSON", nargs="+", help="print the table of earlier "
                    "--json files (merged) instead of running (refusals re-read with today's "
                    "reasons)")
    args = ap.parse_args(argv)
    if args.table:
        return print_table(args.table)
    args.radius = args.radius or [2.0]
    if not args.fixtures and not args.parts:
        args.fixtures = True
    t0 = time.perf_counter()
    tasks, notes = tasks_for(args)
    tasks.sort(key=lambda t: (t["name"], t["radius"]))
    records = []
    with multiprocessing.get_context("spawn").Pool(max(1, min(args.workers, 2))) as pool:
        for k, rec in enumerate(pool.imap(run_pair, tasks, chunksize=1), 1):
            records.append(rec)
            outcome = ",".join(r["outcome"] for r in rec.get("runs", [])) or rec.get("error")
            print(f"coverage: [{k}/{len(tasks)}] {rec['part']} faces {rec['faces']} R "
                  f"{rec['radius']}: {rec['covered']}/{rec['feasible']} ({outcome}, "
                  f"{rec['seconds']} s)", file=sys.stderr, flush=True)
    elapsed = time.perf_counter() - t0
    print(table(records, notes))
    print(f"\n{len(tasks)} pair runs in {elapsed:.0f} s (wall, {min(args.workers, 2)} workers)")
    if args.json:
        with open(args.json + ".tmp", "w") as fh:
            json.dump({"args": vars(args), "seconds": elapsed, "notes": notes,
                       "records": records}, fh, indent=1, default=float)
        os.replace(args.json + ".tmp", args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
