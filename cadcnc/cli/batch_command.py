"""``cadcnc batch JOBFILE``: the job file read (:mod:`cadcnc.batch.job_file`), its parts'
options parsed by their commands' parsers (:mod:`cadcnc.cli.batch_jobs`), one library call
(:func:`cadcnc.batch.engine.run_batch`), the summary printed, the batch's exit code."""

from __future__ import annotations

from cadcnc.batch import job_file
from cadcnc.batch.engine import run_batch
from cadcnc.batch.records import batch_exit, summary_table
from cadcnc.core.work_limits import sigterm_as_interrupt

from .batch_jobs import batch_parts
from .feedback import say_error


def batch(args) -> int:
    job = job_file.read(args.jobfile)
    parts = batch_parts(job, args.commands)
    report = None if args.quiet else (lambda p: say_error(f"cadcnc: batch: {p}"))
    with sigterm_as_interrupt():   # the local cluster shut down as after Ctrl-C
        records = run_batch(parts, job.out, scheduler=args.scheduler, workers=args.workers,
                            force=args.force, progress=report, inputs=[args.jobfile])
    code = batch_exit(records)
    if not args.quiet:
        print(summary_table(records))
        print(f"wrote {job.out / 'summary.csv'}, {job.out / 'summary.json'}; exit {code}")
    return code
