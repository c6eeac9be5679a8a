"""What the commands tell the user while they work: errors and progress on stderr."""

from __future__ import annotations

import sys
import time


def say_error(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def progress(args, label: str):
    """A progress(cycles, mm) callback printing to stderr, or None with --quiet."""
    if args.quiet:
        return None

    def report(cycles: int, mm: float) -> None:
        say_error(f"cadcnc: {label}: {cycles} cycles, {mm:.1f} mm")

    return report


def stage_progress(args, label: str, after_s: float = 0.0):
    """A progress(stage, done, total) callback: one stderr line per stage (the stages
    count differently) once ``after_s`` seconds have passed, or None with --quiet."""
    if args.quiet:
        return None
    seen = set()
    start = time.monotonic()

    def report(stage: str, done: int, total: int) -> None:
        if stage not in seen and time.monotonic() - start >= after_s:
            seen.add(stage)
            say_error(f"cadcnc: {label}: {stage} ...")

    return report
