"""``cadcnc batch JOBFILE``'s options: many parts, each with its operations, on Dask
(docs/batch.md); the command is :func:`cadcnc.cli.batch_command.batch`.

The job file is read and every part's every operation turned into a Job before any work:
each operation's options go through the parser of its own command (``cadcnc pencil
--help`` lists them), so a job file takes exactly the command line's options, and a
mistake is named by its line and key (exit 2). Then one library call,
:func:`cadcnc.run_batch`, the summary printed, and the batch's exit code.
"""

from __future__ import annotations


def add_parser(add, commands) -> None:
    """Register ``batch`` with ``add(name, help, description)`` (:mod:`cadcnc.cli.app`);
    ``commands``: the parser of every command, which reads a job file's options."""
    p = add("batch", "run many parts from a job file, on Dask (this machine or a cluster)",
            "Run every part of a job file (TOML or JSON: parts, operations and their "
            "options; docs/batch.md), one Dask task per part, each part's outputs in its "
            "own folder; print the summary (also OUT/summary.csv and .json). Parts whose "
            "outputs exist and whose job is unchanged are skipped. Exit codes: "
            "docs/reliability.md (0 every part complete and verified, 2 a bad job file, "
            "6 some parts failed).")
    p.add_argument("jobfile", metavar="JOBFILE", help="the job file (.toml or .json)")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                   help="an existing Dask scheduler (default: a local cluster of worker "
                        "processes on this machine, loopback only)")
    p.add_argument("--workers", type=int, metavar="N",
                   help="worker processes of the local cluster (default: one per core, "
                        "at most one per part)")
    p.add_argument("--force", action="store_true",
                   help="run every part again, unchanged ones too")
    p.set_defaults(commands=commands)
