"""The whole ``cadcnc finish`` command per point against OpenCAMLib's drop-cutter (issue 24).

The free-form slab (benchmarks/finishing/freeform_slab.py), R 3, stepover 1 mm: the
command as a user runs it (a new process: start-up, reading the part, computation, the
gate, writing the G-code and the JSON), its wall time per point of the program written,
at ``--jobs 1`` and at the default (every core); against OpenCAMLib's BatchDropCutter (one
thread) on the same pass lines, points 0.1 mm apart, its time per point with the
tessellation at ``--tol`` (1e-3 mm) included (benchmarks/finishing/finish_vs_ocl.py's
tools). Needs ``pip install -e '.[bench]'``.

    nice python -m benchmarks.pace.command_vs_ocl [--tol 1e-3] [--jobs 1 0]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import cadcnc
from benchmarks.finishing.finish_bench_tools import run_ocl, tessellate
from benchmarks.finishing.finish_vs_ocl import ocl_points, plane_frame
from benchmarks.pace.bench_pace import slab_case
from cadcnc.io.program_json import read_program


def command(path: str, top: int, out: str, jobs: int) -> float:
    """Wall seconds of ``cadcnc finish`` writing ``out`` (.json) and its G-code."""
    args = [sys.executable, "-m", "cadcnc.cli", "finish", path, "--faces", str(top),
            "--radius", "3", "--stepover", "1", "-q", "-o", out, "-o", out[:-5] + ".ngc"]
    if jobs:
        args += ["--jobs", str(jobs)]
    t0 = time.perf_counter()
    subprocess.run(args, check=True, env={**os.environ, "CADCNC_JOBS": ""})
    return time.perf_counter() - t0


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tol", type=float, default=1e-3)
    ap.add_argument("--jobs", type=int, nargs="+", default=[1, 0], help="0: the default")
    args = ap.parse_args(argv)
    print(f"load {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as folder:
        path, job = slab_case(folder)
        top = job.operation.faces[0]
        out = os.path.join(folder, "slab.json")
        ours = {}
        for jobs in args.jobs:
            seconds = command(path, top, out, jobs)
            program = read_program(out)
            points = sum(len(c.points) for c in program.cuts)
            ours[jobs] = 1e6 * seconds / points
            print(f"cadcnc finish --jobs {jobs or 'default'}: {seconds:.1f} s, {points} points,"
                  f" {ours[jobs]:.1f} us per point", flush=True)
        _, normal = plane_frame(0.0)
        offsets = [float(np.round(np.median(c.points @ normal), 9)) for c in program.cuts]
        topods = [cadcnc.load_step(path).face(top).topods]
        xy, _ = ocl_points(topods, offsets, 0.0)
        tris, mesh_s = tessellate(topods, args.tol)
        ocl = run_ocl(tris, xy, 3.0, threads=1)
        total = mesh_s + sum(ocl.seconds.values())
        per = 1e6 * total / len(xy)
        print(f"OpenCAMLib at {args.tol:g} mm: {len(tris)} triangles, {len(xy)} points, "
              f"{total:.1f} s with the tessellation ({mesh_s:.1f} s), {per:.1f} us per point")
        for jobs, us in ours.items():
            print(f"  OpenCAMLib / cadcnc finish --jobs {jobs or 'default'}: {per / us:.2f}x")
    print(f"load {os.getloadavg()}")


if __name__ == "__main__":
    main()
