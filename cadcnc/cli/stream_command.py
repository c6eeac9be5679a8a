"""``cadcnc stream``: the options read, one pipeline call
(:func:`cadcnc.pipeline.streaming.stream_saved`), the stream's summary printed; and the
printing of a stream for the operations' ``--stream OUT``."""

from __future__ import annotations

from cadcnc.core.errors import InputError
from cadcnc.core.units import check_number, parse_feed
from cadcnc.pipeline.streaming import StreamRun, stream_saved

from .feedback import say_error
from .options import machine_of, tolerances


def stream(args) -> int:
    if not args.output and not args.hal:
        raise InputError("stream: give -o OUT (.npy or .txt), --hal, or both")
    if args.max_periods < 1:
        raise InputError(f"--max-periods must be at least 1, got {args.max_periods}")
    machine = machine_of(args)
    run = stream_saved(args.program, args.part, machine, args.output or [],
                       tolerances=tolerances(args), flip_material=args.flip_material,
                       say=None if args.quiet else say_error, ini=args.machine,
                       feed=None if args.feed is None else parse_feed(args.feed),
                       planned=not args.constant_feed, allow_gouge=args.allow_gouge,
                       hal=args.hal, max_periods=args.max_periods,
                       blend=parse_blend(args.blend))
    print_stream(run, str(args.program), args.quiet)
    return run.code


def parse_blend(text: str) -> float:
    """``--blend MM`` as a number >= 0 (InputError otherwise: negative, NaN, not a number)."""
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"--blend must be a number >= 0 mm, got {text!r}") from None
    return check_number("--blend", value, "mm", allow_zero=True)


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
             "interpolated from their points (roll-over arcs)"]
    for what in ("velocity", "acceleration", "jerk"):
        shares = s[f"max_{what}_share"]
        lines.append(f"  max {what:<12} " + ", ".join(
            f"{axis} {100 * v:.1f} %" for axis, v in shares.items()) + " of the limit")
    return "\n".join(lines)
