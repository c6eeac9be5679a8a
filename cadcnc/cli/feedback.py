"""What the commands tell the user while they work: errors and progress on stderr."""

from __future__ import annotations

import sys
import time

from cadcnc.core.work_limits import HEARTBEAT_S, Heartbeat


def say_error(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def progress(args, label: str):
    """A path's :data:`~cadcnc.core.progress.Progress` (``done`` cycles, ``what`` the mm
    travelled) printing to stderr, or None with --quiet."""
    if args.quiet:
        return None

    def report(done: int, total: int, what: str) -> None:
        say_error(f"cadcnc: {label}: {done} cycles, {what}")

    return report


def stage_progress(args, label: str, after_s: float = 0.0, clock=time.monotonic):
    """A :data:`~cadcnc.core.progress.Progress` ``(done, total, stage)``: one stderr line when a stage starts (once
    ``after_s`` seconds have passed) and then at least every HEARTBEAT_S seconds while
    it runs, with its count; None with --quiet. ``clock`` is injectable for tests."""
    if args.quiet:
        return None
    seen = set()
    start = clock()
    beat = Heartbeat(say_error, HEARTBEAT_S, clock)

    def report(done: int, total: int, stage: str) -> None:
        if clock() - start < after_s:
            return
        text = f"cadcnc: {label}: {stage} ..." if stage not in seen else \
            f"cadcnc: {label}: {stage} {done}/{total}"
        if beat.beat(text, force=stage not in seen):
            seen.add(stage)

    return report
