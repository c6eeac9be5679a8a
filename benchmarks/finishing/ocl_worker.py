"""OpenCAMLib's drop-cutter on a triangle file, in a process of its own.

Run by benchmarks/finishing/finish_vs_ocl.py: opencamlib from PyPI crashed when loaded in the same
process as cadquery's OCCT libraries, so this script imports numpy and opencamlib only.

    python -m benchmarks.finishing.ocl_worker IN.npz OUT.npz

IN.npz: ``triangles`` (T, 3, 3) mm, ``points`` (N, 2) x, y of the cutter locations,
``radius`` (ball radius R, mm), ``length`` (cutter length, mm), ``z0`` (start height of
every cutter location, below the mesh), ``threads``. OUT.npz: ``cl`` (N, 3) tool-tip
cutter locations (the ball centre is CL + R z), ``seconds`` = [building the STLSurf,
appending the points, BatchDropCutter.run], ``threads`` as OCL reports it.
"""

from __future__ import annotations

import sys
import time

import numpy as np
import opencamlib as ocl


def drop(triangles: np.ndarray, points: np.ndarray, radius: float, length: float,
         z0: float, threads: int) -> tuple[np.ndarray, list[float], int]:
    """(cl (N, 3), [stl s, append s, run s], threads used) of BatchDropCutter."""
    t0 = time.perf_counter()
    surf = ocl.STLSurf()
    for a, b, c in triangles.tolist():
        surf.addTriangle(ocl.Triangle(ocl.Point(*a), ocl.Point(*b), ocl.Point(*c)))
    t1 = time.perf_counter()
    # OCL takes the diameter, as floats; it returns tool-tip points
    cutter = ocl.BallCutter(float(2.0 * radius), float(length))
    bdc = ocl.BatchDropCutter()
    bdc.setSTL(surf)
    bdc.setCutter(cutter)
    bdc.setThreads(int(threads))
    keep = []  # BatchDropCutter keeps pointers to the appended CLPoints: keep them alive
    for x, y in points.tolist():
        cl = ocl.CLPoint(float(x), float(y), float(z0))
        keep.append(cl)
        bdc.appendPoint(cl)
    t2 = time.perf_counter()
    bdc.run()
    t3 = time.perf_counter()
    out = np.array([(p.x, p.y, p.z) for p in bdc.getCLPoints()], dtype=float)
    return out, [t1 - t0, t2 - t1, t3 - t2], int(bdc.getThreads())


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    data = np.load(argv[0])
    cl, seconds, threads = drop(data["triangles"], data["points"], float(data["radius"]),
                                float(data["length"]), float(data["z0"]),
                                int(data["threads"]))
    np.savez(argv[1], cl=cl, seconds=np.array(seconds), threads=threads)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
