"""What the commands tell the user while they work: errors and progress on stderr."""

from __future__ import annotations

import sys


def say_error(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def progress(args, label: str):
    """A progress(cycles, mm) callback printing to stderr, or None with --quiet."""
    if args.quiet:
        return None

    def report(cycles: int, mm: float) -> None:
        say_error(f"cadcnc: {label}: {cycles} cycles, {mm:.1f} mm")

    return report
