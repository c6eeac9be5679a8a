"""``cadcnc stream``: the options read, one pipeline call
(:func:`cadcnc.pipeline.streaming.stream_saved`), the stream's summary printed
(:mod:`.stream_report`)."""

from __future__ import annotations

from cadcnc.core.errors import InputError
from cadcnc.core.units import check_number, parse_feed
from cadcnc.pipeline.streaming import stream_saved

from .feedback import say_error
from .options import machine_of, tolerances
from .stream_report import print_stream


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
