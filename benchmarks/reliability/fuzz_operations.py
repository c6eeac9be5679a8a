"""The operation fuzz, longer: `pencil` and `finish` through the CLI on random settings,
every exit 0 and 5 judged independently (cadcnc.testing.moves_judge).

    python -m benchmarks.reliability.fuzz_operations --trials 500 --out fuzz.json

Prints the exits, the deepest reach of any exit-0 program beyond its gouge limit (must be
none), refusals the judge does not back (must be none), tracebacks and hangs; the test
suite runs the same property on a few derandomized draws
(tests/reliability/test_fuzz_operations.py).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import random
import signal
import sys
import tempfile
import time
from pathlib import Path

from benchmarks import FIXTURES
from cadcnc.testing.moves_judge import deepest

CASES = [   # (command, part file, extra options)
    ("pencil", "step_block.step", []),
    ("pencil", "pocket.step", ["--faces", "10", "17", "11"]),
    ("finish", "finish_ridge.step", ["--faces", "3", "4"]),
]
GOUGES = ("0.0005", "0.001", "0.1")
CHORDS = (None, "0.0005", "0.002")
DEFINED = {0, 2, 3, 5, 6}
TRIAL_S = 300   # a trial still running after this is a hang


def cli(*args) -> tuple[int, str]:
    """(exit code, stderr) of ``cadcnc ARGS`` run in this process."""
    from cadcnc.cli import main

    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = main([str(a) for a in args])
        except SystemExit as e:
            code = e.code
    return int(code or 0), err.getvalue()


def trial_args(case, radius: float, stepover: float, gouge: str, chord, top: float,
               lift: float, out: Path) -> list:
    """The command line of one draw (see the module doc)."""
    command, name, extra = case
    args = [command, FIXTURES / name, *extra, "--radius", f"{radius:.6g}",
            "--gouge-tolerance", gouge, "--clearance", f"{top + radius + lift:.6g}",
            "-o", out, "-q"]
    if command == "finish":
        args += ["--stepover", f"{stepover:.4g}"]
    if chord is not None:
        args += ["--tolerance", chord]
    return args


def judged(args: list, part, radius: float, gouge: str, run=cli) -> dict:
    """Run one draw and judge it: {exit, stderr, depth (mm, exits 0 and 5), ok}."""
    out = Path(args[args.index("-o") + 1])
    code, err = run(*args)
    result = dict(exit=code, stderr=err.strip()[:300], depth=None,
                  ok=code in DEFINED and "Traceback" not in err)
    if code == 0:
        result["depth"] = deepest(part, out.read_text(), radius)
        result["ok"] &= result["depth"] <= float(gouge)
    elif code == 5:
        again, _ = run(*args, "--allow-gouge")
        result["depth"] = deepest(part, out.read_text(), radius) if out.exists() else None
        result["ok"] &= again == 5 and result["depth"] is not None and \
            result["depth"] > float(gouge)
    else:
        result["ok"] &= not out.exists()
    return result


def main(argv=None) -> int:
    import cadcnc

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=500)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=Path("fuzz_operations.json"))
    a = ap.parse_args(argv)
    rng = random.Random(a.seed)
    parts = {name: cadcnc.load_step(FIXTURES / name) for _, name, _ in CASES}
    results = []

    def timeout(*_):
        raise TimeoutError(f"trial over {TRIAL_S} s")

    signal.signal(signal.SIGALRM, timeout)
    t0 = time.time()
    for k in range(a.trials):
        case = rng.choice(CASES[:2] * 3 + CASES[2:])
        radius = 10.0 ** rng.uniform(-3.0, 3.0)
        draw = dict(case=case[:2], radius=radius, stepover=rng.uniform(6.0, 12.0),
                    gouge=rng.choice(GOUGES), chord=rng.choice(CHORDS),
                    lift=rng.uniform(-2.0, 30.0))
        with tempfile.TemporaryDirectory() as tmp:
            args = trial_args(case, radius, draw["stepover"], draw["gouge"], draw["chord"],
                              parts[case[1]].top, draw["lift"], Path(tmp) / "p.ngc")
            signal.alarm(TRIAL_S)
            t = time.time()
            try:
                r = judged(args, parts[case[1]], radius, draw["gouge"])
            except TimeoutError as e:
                r = dict(exit=None, stderr=str(e), depth=None, ok=False, hang=True)
            except Exception as e:  # noqa: BLE001 - a traceback is a finding
                r = dict(exit=None, stderr=f"{type(e).__name__}: {e}", depth=None, ok=False)
            signal.alarm(0)
        results.append({**draw, **r, "seconds": round(time.time() - t, 2)})
        a.out.write_text(json.dumps(results, indent=1))
        print(f"{k + 1}/{a.trials} {case[0]} R {radius:.3g}: exit {r['exit']} "
              f"{'ok' if r['ok'] else 'BAD'} ({time.time() - t0:.0f} s)", flush=True)
    exits: dict = {}
    for r in results:
        exits[str(r["exit"])] = exits.get(str(r["exit"]), 0) + 1
    bad = [r for r in results if not r["ok"]]
    print(f"trials {len(results)}; exits {exits}; exit 0 share "
          f"{exits.get('0', 0) / max(len(results), 1):.0%}; not ok {len(bad)}")
    return 0 if not bad else 1


if __name__ == "__main__":
    sys.exit(main())
