"""A stream's report on the terminal: its summary, the files written, the HAL run's report.

Shared by ``cadcnc stream`` and the operations' ``--stream``; it imports no planner, so
that an operation that streams nothing does not load one.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .feedback import say_error

if TYPE_CHECKING:
    from cadcnc.pipeline.streaming import StreamRun


def print_stream(run: StreamRun, name: str, quiet: bool) -> None:
    """The stream's summary and files written (stdout, unless ``quiet``), the HAL run's
    report (also when quiet if it fell short), the messages on stderr."""
    if run.stream is not None and not quiet:
        print(summary_text(run.stream, name))
        if run.written:
            print(f"  wrote      {', '.join(run.written)}")
    if run.hal_report is not None and (not quiet or run.fell_short):
        print(run.hal_report)
    for line in run.messages:
        say_error(line)


def summary_text(stream, name: str) -> str:
    """The stream's summary for the user: time, periods, shares of the limits."""
    s = stream.summary()
    kind = "planned feed" if stream.plan.planned else "constant feed (limits ignored)"
    lines = [f"{name}: {kind}, machine {s['machine'] or 'default'}",
             f"  cycle      {s['cycle_time_s']:.3f} s, {s['periods']} periods of "
             f"{s['period_s'] * 1e3:g} ms; at the programmed feed {s['programmed_time_s']:.3f} "
             f"s, lost to the limits {s['time_lost_s']:.3f} s",
             f"  cuts       {s['kernel_cuts']} re-run by the kernel, {s['hermite_cuts']} "
             "interpolated from their points (roll-over arcs, cuts under 0.01 mm)"]
    for what in ("velocity", "acceleration", "jerk"):
        shares = s[f"max_{what}_share"]
        lines.append(f"  max {what:<12} " + ", ".join(
            f"{axis} {100 * v:.1f} %" for axis, v in shares.items()) + " of the limit")
    return "\n".join(lines)
