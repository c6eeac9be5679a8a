"""Two serial stages timed inside real runs (issue 24): the pencil's ``order_cuts`` and the
finishing's ``uncut_report``, with the SHA-256 of each program's JSON so that two commits
can be compared (the same bytes before and after a change that must not alter them).

    nice python -m benchmarks.pace.bench_serial [--slab] [--pencil PART.stp] [--repeat 3]

The slab is benchmarks/finishing/freeform_slab.py's (R 3, stepover 1, as bench_pace); the
pencil is R 3 on the part (r0901_ec: about 2.5 minutes). Each stage is called once by the
run and then ``--repeat`` times more on the same arguments: the least CPU time is printed
with os.getloadavg(). Run it on two commits (``git stash`` / ``git checkout``) to compare.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import tempfile
import time

import cadcnc
from benchmarks.pace.bench_pace import pencil_case, slab_case
from cadcnc.io.outputs import render
from cadcnc.ops.finish import finish
from cadcnc.ops.pencil import pencil_program as pencil  # the module


def timed_stage(module, name: str, calls: list):
    """Replace ``module.name`` by a wrapper recording its arguments in ``calls``."""
    real = getattr(module, name)

    def wrapper(*args):
        calls.append(args)
        return real(*args)
    setattr(module, name, wrapper)
    return real


def least_cpu(fn, args, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t = time.process_time()
        fn(*args)
        best = min(best, time.process_time() - t)
    return best


def run_case(label: str, path: str, job, module, name: str, repeat: int,
             folder: str = "") -> None:
    """Run ``job`` on ``path`` at jobs=1 timing ``module.name``; ``folder``: a temporary
    folder named in the JSON (taken out of the digest)."""
    calls: list = []
    real = timed_stage(module, name, calls)
    try:
        part = cadcnc.load_step(path)
        program = cadcnc.run(part, job, processes=1)
    finally:
        setattr(module, name, real)
    text = render(program, "p.json", part, "")
    digest = hashlib.sha256(text.replace(folder, "").encode() if folder else
                            text.encode()).hexdigest()
    for args in calls:
        size = len(args[0]) if name == "order_cuts" else len(args[2])
        print(f"{label}: {name} on {size} items: {least_cpu(real, args, repeat):.4f} s CPU "
              f"(least of {repeat}), load {os.getloadavg()}", flush=True)
    print(f"{label}: program JSON sha256 {digest}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--slab", action="store_true")
    ap.add_argument("--pencil", metavar="PART.stp")
    ap.add_argument("--radius", type=float, default=3.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        if args.slab:
            run_case("slab finish", *slab_case(folder), finish, "uncut_report", args.repeat,
                     folder)
        if args.pencil:
            run_case(f"{os.path.basename(args.pencil)} pencil", *pencil_case(
                args.pencil, args.radius), pencil, "order_cuts", args.repeat)


if __name__ == "__main__":
    main()
