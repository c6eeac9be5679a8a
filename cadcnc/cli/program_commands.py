"""``plot`` and ``verify``: programs already computed (or computed for ``verify``), one
pipeline call each (:mod:`cadcnc.pipeline.saved`), the result printed."""

from __future__ import annotations

import json

from cadcnc.core.errors import InputError
from cadcnc.pipeline.saved import VerifyRun, plot_saved, verify_program

from .feedback import progress, say_error, stage_progress
from .options import path_job, tolerances


def plot(args) -> int:
    plot_saved(args.path_json, args.part, args.output)
    if not args.quiet:
        print(f"wrote {args.output}")
    return 0


def verify(args) -> int:
    """Verify every cut of a program (computed, or read from JSON) against OCCT; one
    report per cut. Exit 5 when any cut or link gouges beyond --gouge-tolerance."""
    tol = tolerances(args)
    saved = args.input.lower().endswith(".json")
    if not saved and args.part is not None:
        raise InputError("--part is for a saved PATH.json; a STEP input is the part")
    run = verify_program(args.input, tol, part_file=args.part,
                         job=None if saved else path_job(args, args.input),
                         progress=progress(args, "verify"),
                         cut_progress=lambda: stage_progress(args, "verify"),
                         links_progress=lambda: stage_progress(args, "verify: links", after_s=1.0))
    _print_reports(run, tol, args.json)
    for line in run.messages:
        say_error(line)
    return run.code


def _print_reports(run: VerifyRun, tol, as_json: bool) -> None:
    """One report per cut: a table each, or JSON (one object, or every cut's)."""
    if as_json:
        data = [r.to_dict() for r in run.reports]
        print(json.dumps(data[0] if len(data) == 1 else {
            "ok": all(r.ok(tol.gouge) for r in run.reports),
            "cuts": [{"cut": lab, **d} for lab, d in zip(run.labels, data)]}, indent=1))
        return
    for lab, r in zip(run.labels, run.reports):
        print((f"{lab}\n" if len(run.reports) > 1 else "") + r.format_table(tol.gouge))
