"""``python benchmarks/pace/gate_wave_child.py STEP FACE``, run with ``PYTHONPATH`` a
checkout (this one or the previous code's): the computation and the gate of ``cadcnc
finish STEP --faces FACE --radius 3 --stepover 1`` at one process, as the CLI runs them
(the gate: ``settled_and_judged``, the cut-back and the program gate),
each in CPU seconds of this process; prints one JSON line (points, compute_cpu_s,
gate_cpu_s, the cuts' verdicts and the G-code's SHA-256). Imports only what both
checkouts have."""

from __future__ import annotations

import hashlib
import json
import sys
import time

import cadcnc
from cadcnc.core.job import Job, Raster, Tool
from cadcnc.io.gcode import blend_for
from cadcnc.io.outputs import render
from cadcnc.pipeline.operate import Settings, settled_and_judged


def main(path: str, face: int) -> None:
    part = cadcnc.load_step(path)
    job = Job(Tool(3.0, 0.0), 1500.0, 0.004, Raster((face,), 1.0, None, 0.0, "zigzag"),
              source=path)
    c0 = time.process_time()
    program = cadcnc.run(part, job, processes=1)
    c1 = time.process_time()
    gcode = dict(tolerance=None, tool_tip=False, blend=blend_for(job.tolerances.gouge))
    back, verdict = settled_and_judged(program, part, job, "finish", "finish",
                                       Settings(gcode=gcode, processes=1))
    result = verdict.gate
    c2 = time.process_time()
    text = render(back, "p.ngc", part, "", **gcode)
    print(json.dumps({
        "points": sum(len(c.points) for c in program.cuts), "compute_cpu_s": c1 - c0,
        "gate_cpu_s": c2 - c1, "verdicts": [[r.ok, r.message] for r in result.results],
        "depths": [r.depth_mm for r in result.results],
        "gcode_sha256": hashlib.sha256(str(text).encode()).hexdigest()}))


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]))
