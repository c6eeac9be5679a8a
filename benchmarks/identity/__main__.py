"""``python -m benchmarks identity``: are the programs the same bytes as recorded?

    python -m benchmarks identity [--tier fast|slow|all] --check tests/data/program_digests.json
    python -m benchmarks identity --shared /work/shared/parts \\
        --check benchmarks/identity/shared_digests.json
    python -m benchmarks identity --shared DIR --record FILE     # after an intended change
    python -m benchmarks identity --list

Without ``--shared`` the cases are the fixtures' (``--tier``: ``fast``, ``slow`` or
``all``, the default), with their parts from ``fixtures/``; with ``--shared DIR`` the ten
public parts' cases, their parts from DIR. ``--check FILE`` runs every selected case
(``--only NAME...`` some of them) and prints ``OK`` or ``CHANGED`` per case, with a line
per differing file; the exit code is 1 if any case differs, 0 if all match. ``--record
FILE`` writes the digests of the selected cases (merged into FILE if it exists, so that
``--only`` re-records some cases). ``--keep DIR`` keeps each case's folder;
``--python PY`` runs another checkout's ``cadcnc`` (``PY -m cadcnc.cli``); ``--jobs N``
runs the operations at ``--jobs N`` (a check at N > 1 compares with the record made at 1,
except the command lines).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

from .cases import GROUPS
from .harness import FORMAT, VERSION, compare, expected_exits, git_commit, read_digests, run_case

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "fixtures"


def selected(args) -> tuple[list, Path]:
    if args.shared:
        cases, base = GROUPS["shared"], Path(args.shared)
    else:
        tiers = ["fast", "slow"] if args.tier == "all" else [args.tier]
        cases, base = [c for t in tiers for c in GROUPS[t]], FIXTURES
    if args.only:
        known = {c.name for c in cases}
        unknown = [n for n in args.only if n not in known]
        if unknown:
            raise SystemExit(f"identity: unknown case(s) {unknown}; --list names them")
        cases = [c for c in cases if c.name in args.only]
    return cases, base


def record(args, cases, base) -> int:
    path = Path(args.record)
    doc = read_digests(path) if path.exists() else {"format": FORMAT, "version": VERSION}
    doc.setdefault("note", "SHA-256 of every file each case's cadcnc commands write, and "
                           "their exit codes: benchmarks/identity/README.md")
    doc.setdefault("cases", {})
    bad = 0
    total = 0.0
    for case in cases:
        result = run_case(case, base, python=args.python, keep=args.keep,
                          jobs=args.jobs)
        total += result.cpu_s
        want = expected_exits(case)
        flag = "" if result.exits == want else f"  UNEXPECTED exits (want {want})"
        print(f"{case.name:48s} {result.cpu_s:7.1f} s CPU {result.wall_s:7.1f} s wall "
              f"{len(result.files):3d} files exits {result.exits}{flag}", flush=True)
        if flag:
            bad += 1
            for err in result.stderr:
                if err.strip():
                    print("    " + err.strip().replace("\n", "\n    "))
            continue
        doc["cases"][case.name] = result.record()
    doc["recorded_with_code_at"] = git_commit()
    doc["cases"] = dict(sorted(doc["cases"].items()))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"recorded {len(cases) - bad} case(s) to {path}, {total:.1f} s CPU"
          + (f"; {bad} not recorded (unexpected exit codes)" if bad else ""))
    return 1 if bad else 0


def check(args, cases, base) -> int:
    doc = read_digests(Path(args.check))
    recorded = doc.get("cases", {})
    changed, same, total = 0, 0, 0.0
    for case in cases:
        if case.name not in recorded:
            print(f"CHANGED  {case.name}: not recorded in {args.check}")
            changed += 1
            continue
        result = run_case(case, base, python=args.python, keep=args.keep,
                          jobs=args.jobs)
        total += result.cpu_s
        if args.jobs != 1:   # recorded at --jobs 1: compare the outputs, not the argv
            result = replace(result, argv=case.argvs(1))
        diffs = compare(recorded[case.name], result)
        status = "CHANGED" if diffs else "OK"
        print(f"{status:8s} {case.name}  ({result.cpu_s:.1f} s CPU, "
              f"{len(result.files)} files)", flush=True)
        for line in diffs:
            print("         " + line)
        changed += bool(diffs)
        same += not diffs
    if not args.only and (args.shared or args.tier == "all"):   # the whole set: no leftovers
        defined = {c.name for c in cases}
        for name in sorted(set(recorded) - defined):
            print(f"CHANGED  {name}: recorded but no longer a case")
            changed += 1
    print(f"{same} of {len(cases)} case(s) identical, {changed} changed; {total:.1f} s CPU "
          f"(recorded with the code of {doc.get('recorded_with_code_at', '?')}, "
          f"checked with {git_commit()})")
    return 1 if changed else 0


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks identity", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tier", choices=("fast", "slow", "all"), default="all")
    p.add_argument("--shared", metavar="DIR", help="the public parts' folder")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--record", metavar="FILE")
    g.add_argument("--check", metavar="FILE")
    g.add_argument("--list", action="store_true")
    p.add_argument("--only", nargs="+", metavar="NAME")
    p.add_argument("--keep", metavar="DIR", type=Path)
    p.add_argument("--python", metavar="PY", help="interpreter with cadcnc installed")
    p.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="--jobs of path, pencil and finish (default 1, as recorded)")
    args = p.parse_args(argv)
    cases, base = selected(args)
    if args.record and args.jobs != 1:
        p.error("records are made at --jobs 1")
    if args.list or not (args.record or args.check):
        for case in cases:
            print(case.name)
            for argv_ in case.argvs(args.jobs):
                print("    cadcnc " + " ".join(argv_))
        return 0
    return record(args, cases, base) if args.record else check(args, cases, base)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
