"""``path``, ``pencil`` and ``finish``: options to a Job, one pipeline call
(:func:`cadcnc.pipeline.operation.run_operation`; ``pencil --setups`` in
:mod:`.setups_command`, loaded through the command table), the verdict and the summary
printed, the pipeline's exit code.
"""

from __future__ import annotations

import time
from pathlib import Path

from cadcnc.geometry.setup import setup_in
from cadcnc.pipeline.operation import OperationRun, StreamRequest, run_operation

from .commands import load
from .feedback import progress, say_error, stage_progress
from .options import finish_job, machine_of, path_job, pencil_job, settings_of
from .stream_report import print_stream

SETUPS = "cadcnc.cli.setups_command:setups"
"""``pencil --setups``' handler: its pencil and setup modules imported only then."""
PROGRESS_EVERY_S = 1.0  # s between two progress lines of finish on stderr


def path(args) -> int:
    i, j = args.faces
    return _operation(args, "path", path_job(args, args.step),
                      progress=progress(args, f"faces {i} {j}"))


def pencil(args) -> int:
    if args.setups is not None:
        return load(SETUPS)(args)
    report = None if args.quiet else (
        lambda done, total, what: say_error(f"cadcnc: pencil: corner {done}/{total} ({what})"))
    return _operation(args, "pencil", pencil_job(args, args.step), progress=report, times={})


def finish(args) -> int:
    return _operation(args, "finish", finish_job(args, args.step),
                      progress=_finish_progress(args))


def _operation(args, what: str, job, *, progress=None, times: dict | None = None) -> int:
    """One operation's run: the options' Job, one pipeline call, the summary printed."""
    stream = None if not getattr(args, "stream", None) else StreamRequest(
        tuple(args.stream), machine_of(args))
    run = run_operation(args.step, job, what, args.output, settings_of(args), stream=stream,
                        progress=progress, times=times, say=None if args.quiet else say_error,
                        gate_progress=stage_progress(args, f"{what}: gouge check",
                                                     after_s=1.0))
    _print_operation(args, run, times)
    if run.stream is not None:
        print_stream(run.stream, Path(args.step).name, args.quiet)
    return run.code


def _print_operation(args, run: OperationRun, times: dict | None) -> None:
    """The verdict's messages on stderr; the summary, verdict and times on stdout."""
    done, verdict = run.outcome, run.outcome.verdict
    for line in verdict.messages:
        say_error(line)
    if not args.quiet:
        print(done.program.summary(Path(args.step).name))
        if setup_in(done.part) is not None:
            print("  setup      " + "; ".join(setup_in(done.part).describe()))
        print("  verdict    " + ("written" if verdict.write else "nothing written") + (
            "" if verdict.code == 0 else f" (exit {verdict.code}: see the message above)"))
        staged = "" if not times else "; " + ", ".join(f"{k} {v:.1f} s"
                                                       for k, v in times.items())
        print(f"  time       computed in {done.seconds_computed:.1f} s, gated in "
              f"{done.seconds_gated:.1f} s{staged}")
        if run.written:
            print(f"  wrote      {', '.join(run.written)}")
    for line in run.messages:
        say_error(line)


def _finish_progress(args):
    """A progress(done, total, what) callback: a stderr line at most every second, and
    the last plane, or None with --quiet."""
    if args.quiet:
        return None
    last = [time.monotonic()]

    def report(done: int, total: int, what: str) -> None:
        now = time.monotonic()
        if now - last[0] >= PROGRESS_EVERY_S or done == total:
            last[0] = now
            say_error(f"cadcnc: finish: plane {done}/{total} ({what})")

    return report
