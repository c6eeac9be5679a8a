"""``python -m benchmarks perf [--quick | --full] ...``: regenerate docs/performance.md's
tables (benchmarks/perf.py). ``python -m benchmarks profile [CASE...] [--base DIR]``: each
stage's CPU time and the OCCT calls of a corner path, a pencil and a setups run
(benchmarks/profile/bench_profile.py). ``python -m benchmarks identity [--shared DIR]
[--record FILE | --check FILE]``: the programs' SHA-256 against a record
(benchmarks/identity/README.md). Each benchmark also runs alone, e.g.
``python -m benchmarks.kernel.bench_kernel``; benchmarks/README.md lists them."""

from __future__ import annotations

import sys

USAGE = __doc__


def main(argv: list[str]) -> int:
    if not argv or argv[0] in ("-h", "--help"):
        print(USAGE)
        return 0 if argv else 2
    if argv[0] == "profile":
        from benchmarks.profile.bench_profile import main as profile  # noqa: PLC0415

        return profile(argv[1:])
    if argv[0] == "identity":
        from benchmarks.identity.__main__ import main as identity  # noqa: PLC0415

        return identity(argv[1:])
    if argv[0] != "perf":
        print(f"unknown command {argv[0]!r}\n\n{USAGE}", file=sys.stderr)
        return 2
    from benchmarks.perf import main as perf  # noqa: PLC0415 - imports OCCT

    return perf(argv[1:])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
