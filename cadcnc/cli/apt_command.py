"""``cadcnc run``: an APT-like part program; the options read, one pipeline call
(:mod:`cadcnc.pipeline.apt_run`), each path's summary printed."""

from __future__ import annotations

import sys
from pathlib import Path

from cadcnc.core.errors import InputError
from cadcnc.pipeline.apt_run import run_apt, stream_apt

from .feedback import progress, say_error, stage_progress
from .options import clearance, gcode_keywords, tolerances, wants_gcode


def run(args) -> int:
    """Execute an APT-like program: each PATH as a program of one cut, judged by the
    library's gate; written, summarised, or streamed with ``--stream``."""
    requested = args.output or []
    if args.stream and requested:
        raise InputError("--stream prints increments instead of writing files: give "
                         "either --stream or -o")
    if args.stream:
        code = stream_apt(args.program, tolerances(args), clearance(args), sys.stdout.write,
                          say_error, allow_partial=args.allow_partial,
                          allow_gouge=args.allow_gouge)
        sys.stdout.flush()
        return code
    done = run_apt(args.program, requested, tolerances(args), clearance(args),
                   gcode=gcode_keywords(args) if wants_gcode(requested) else None,
                   allow_partial=args.allow_partial, allow_gouge=args.allow_gouge,
                   progress_of=lambda label: progress(args, label),
                   gate_progress_of=lambda label: stage_progress(args, label, after_s=1.0))
    if not args.quiet:
        for entry, program in done.paths:
            print(f"PATH {entry.name} (line {entry.line}): "
                  + program.summary(Path(entry.job.source or "").name))
    for line in done.messages:
        say_error(line)
    if done.written and not args.quiet:
        print(f"wrote {', '.join(done.written)}")
    return done.code
