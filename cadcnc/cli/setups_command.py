"""``pencil --setups``: one program per setup (:func:`cadcnc.pipeline.setup_programs.run_setups`),
each setup's summary, the choice and the verdict printed, the pipeline's exit code."""

from __future__ import annotations

from pathlib import Path

from cadcnc.core.errors import InputError
from cadcnc.core.units import parse_length
from cadcnc.pipeline.setup_programs import SetupsRun, run_setups

from .feedback import say_error, stage_progress
from .options import pencil_job, settings_of


def setups(args) -> int:
    """``pencil --setups``: one program per setup (:mod:`cadcnc.pipeline.setup_programs`)."""
    if getattr(args, "axis", None) is not None:
        raise InputError("give --axis or --setups, not both")
    if getattr(args, "stream", None):
        raise InputError("--stream takes one program: stream a setup's with --axis")
    overlap = parse_length(args.setup_overlap, "--setup-overlap")
    run = run_setups(args.step, pencil_job(args, args.step), args.setups, overlap,
                     args.output, settings_of(args),
                     progress=None if args.quiet else (lambda done, total, what: None),
                     gate_progress=lambda what: stage_progress(
                         args, f"{what}: gouge check", after_s=1.0))
    _print_setups(args, run)
    return run.code


def _print_setups(args, run: SetupsRun) -> None:
    """The messages on stderr; each setup's summary, the choice, verdict and times."""
    for line in run.messages:
        say_error(line)
    if args.quiet:
        return
    name = Path(args.step).name
    for done in run.programs:
        if done.program is not None:
            print(done.program.summary(f"{name} setup {done.setup.name}"))
            print("  setup      " + "; ".join(done.setup.describe()))
    for line in run.result.summary_lines():
        print(line)
    print("verdict    " + ("written: " + ", ".join(run.written) if run.written else
                           "nothing written") + ("" if run.code == 0 else f" (exit {run.code})"))
    print(f"time       computed in {run.seconds_computed:.1f} s, gated in "
          f"{run.seconds_gated:.1f} s")
