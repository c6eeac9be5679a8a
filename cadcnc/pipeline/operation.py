"""One operation as a command runs it: every destination checked before any work, the part
operated and judged (:func:`~cadcnc.pipeline.operate.operate`), the outputs written all at
once when the verdict allows, then, for a complete and verified program, its stream
(:func:`~cadcnc.pipeline.streaming.stream_to`). The worker processes end with the run.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..core.errors import EXIT_OK
from ..core.job import Job
from ..io.output_set import OutputSet, check_destination
from ..io.outputs import SUFFIXES
from ..parallel.pool import kept_pools
from .operate import Outcome, Settings, operate, rendered


@dataclass(frozen=True)
class StreamRequest:
    """``--stream OUT``: the stream's ``outputs`` (.npy, .txt) and the ``machine``
    (:class:`~cadcnc.controller.machine.Machine`) whose limits plan the feed."""

    outputs: tuple[str, ...]
    machine: object


@dataclass
class OperationRun:
    """What :func:`run_operation` left: the ``outcome`` (part, program, verdict, seconds),
    the files ``written``, the ``stream`` (None when none was asked or the program was not
    streamed), ``messages`` for the user besides the verdict's, and the exit ``code``."""

    outcome: Outcome
    written: list[str] = field(default_factory=list)
    stream: object = None
    messages: list[str] = field(default_factory=list)
    code: int = EXIT_OK


def run_operation(step, job: Job, what: str, outputs, settings: Settings = Settings(), *,
                  stream: StreamRequest | None = None, progress=None,
                  times: dict | None = None, gate_progress=None, say=None) -> OperationRun:
    """Run ``job`` on the STEP file ``step`` and write ``outputs`` (module doc). ``what``:
    the command's name in messages; ``progress``, ``times``, ``gate_progress``: as
    :func:`~cadcnc.pipeline.operate.operate`; ``say``: the stream's progress on stderr
    (None: silent). Raises the library's errors."""
    with kept_pools():   # one pool per part for the plan and the gate, ended with the run
        return _run(step, job, what, list(outputs), settings, stream, progress=progress,
                    times=times, gate_progress=gate_progress, say=say)


def _run(step, job, what, outputs, settings, stream, *, progress, times, gate_progress,
         say) -> OperationRun:
    written = OutputSet(outputs, SUFFIXES, inputs=[step])  # checked before computing
    for out in stream.outputs if stream is not None else ():
        from .streaming import SUFFIXES as STREAM_SUFFIXES
        check_destination(out, STREAM_SUFFIXES, [step])
    done = operate(step, job, what, settings, progress=progress, times=times,
                   gate_progress=gate_progress, outputs=outputs)
    run = OperationRun(done, code=done.verdict.code)
    if done.verdict.write:
        written.write(rendered(done, outputs, done.what, settings))
        run.written = outputs
    if stream is None:
        return run
    if run.code != EXIT_OK:
        run.messages.append(f"cadcnc: {done.what}: not streamed: only a complete, verified "
                            "program is")
        return run
    from .streaming import stream_to
    run.stream = stream_to(done.program, done.part, stream.machine, stream.outputs,
                           tolerances=job.tolerances, say=say, inputs=[step])
    run.code = run.stream.code
    return run
