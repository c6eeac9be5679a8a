"""One face pair through cadcnc's program pipeline, as ``cadcnc path`` will run it
(coverage benchmark, ``--via api``; run as a subprocess, one per pair).

    python -m benchmarks.coverage.coverage_run_pair STEP I J RADIUS FEED PERIOD_S OUT

Builds ``Job(Tool(R), feed, period, PairPath(faces=(I, J), edge=None))``, calls
``program_for_job`` (every feasible stretch of every concave edge, cut and linked),
passes every cut through the whole-part gouge gate, and writes the version 2 program
JSON of the cuts that pass (relinked). A cut the gate refuses is dropped, and its
message goes to stderr and to the JSON's ``gate_refused`` (with its points, so the
coverage it would have given can be counted). Exit codes follow the CLI: 0 written,
5 every cut refused by the gate, the error's own code for a refusal (FacePairError...).
"""

from __future__ import annotations

import json
import sys


def main(argv: list[str]) -> int:
    step, i, j, radius, feed, period, out = argv
    import cadcnc
    from cadcnc.core.errors import CadcncError
    from cadcnc.core.job import Job, PairPath, Tool
    from cadcnc.io.program_json import program_to_dict
    from cadcnc.ops.path.pair_program import program_for_job, safe_height
    from cadcnc.program.linking import linked
    from cadcnc.program.program import Program
    from cadcnc.verification import gouge_gate

    try:
        part = cadcnc.load_step(step)
        job = Job(Tool(float(radius)), float(feed), float(period),
                  PairPath(faces=(int(i), int(j)), edge=None))
        program = program_for_job(part, job)
    except CadcncError as e:
        print(f"cadcnc: path: {e}", file=sys.stderr)
        return int(getattr(e, "exit_code", 1))
    kept, refused = [], []
    for cut in program.cuts:
        gate = gouge_gate(cut.path, part, cut.path.job.tolerances)
        if gate.ok:
            kept.append(cut)
            continue
        print(f"cadcnc: path: edge {cut.edge} stretch {cut.stretch}: {gate.message}",
              file=sys.stderr)
        refused.append({"edge": cut.edge, "stretch": cut.stretch, "message": gate.message,
                        "points": cut.path.points.tolist()})
    d = program_to_dict(Program(program.job, linked(kept, safe_height(part, job)),
                                program.skipped, program.notes))
    d["gate_refused"] = refused
    with open(out, "w") as fh:
        json.dump(d, fh)
    for s in program.skipped:
        print(f"cadcnc: path: skipped edge {s.edge}: {s.reason}: {s.detail}", file=sys.stderr)
    if refused and not kept:
        print(f"cadcnc: path: {refused[-1]['message']}", file=sys.stderr)
        return 5
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
