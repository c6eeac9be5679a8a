"""OpenCAMLib's Waterline and AdaptiveWaterline on a triangle file, in a process of its own.

Run by benchmarks/finishing/waterline_vs_ocl.py (opencamlib crashes beside cadquery's
OCCT libraries, so this script imports numpy and opencamlib only; OCL's destructors print
to stdout, which the caller discards).

    python -m benchmarks.finishing.ocl_waterline_worker IN.npz OUT.npz

IN.npz: ``triangles`` (T, 3, 3) mm, ``levels`` (L,) ball-centre heights, ``radius`` (R,
mm), ``length`` (cutter length), ``sampling`` (fibre spacing, mm), ``min_sampling``
(AdaptiveWaterline's finest), ``adaptive`` (0/1), ``threads``. OUT.npz: ``points`` (N, 3)
ball centres of every loop (OCL's tool tips + R z), ``sizes`` (M,) points per loop,
``level_of`` (M,) the level index of each loop, ``seconds`` (L,) per level (setZ, run,
getLoops), ``stl`` s building the STLSurf, ``cpu`` the process's CPU seconds of both.
"""

from __future__ import annotations

import sys
import time

import numpy as np
import opencamlib as ocl


def waterline(triangles, levels, radius, length, sampling, min_sampling, adaptive, threads):
    t0, c0 = time.perf_counter(), time.process_time()
    surf = ocl.STLSurf()
    for a, b, c in triangles.tolist():
        surf.addTriangle(ocl.Triangle(ocl.Point(*a), ocl.Point(*b), ocl.Point(*c)))
    stl = time.perf_counter() - t0
    cutter = ocl.BallCutter(float(2.0 * radius), float(length))   # diameter, floats
    points, sizes, level_of, seconds = [], [], [], []
    for k, zc in enumerate(levels.tolist()):
        t0 = time.perf_counter()
        wl = ocl.AdaptiveWaterline() if adaptive else ocl.Waterline()
        wl.setSTL(surf)
        wl.setCutter(cutter)
        wl.setThreads(int(threads))
        wl.setSampling(float(sampling))
        if adaptive:
            wl.setMinSampling(float(min_sampling))
        wl.setZ(float(zc - radius))   # OCL's z is the tool tip's
        wl.run()
        loops = wl.getLoops()
        got = [[(p.x, p.y, p.z + radius) for p in loop] for loop in loops]
        seconds.append(time.perf_counter() - t0)
        cpu = time.process_time() - c0
        for loop in got:
            points.extend(loop)
            sizes.append(len(loop))
            level_of.append(k)
    return (np.array(points, float).reshape(-1, 3), np.array(sizes, int),
            np.array(level_of, int), np.array(seconds), stl, cpu)


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    d = np.load(argv[0])
    points, sizes, level_of, seconds, stl, cpu = waterline(
        d["triangles"], d["levels"], float(d["radius"]), float(d["length"]),
        float(d["sampling"]), float(d["min_sampling"]), bool(d["adaptive"]),
        int(d["threads"]))
    np.savez(argv[1], points=points, sizes=sizes, level_of=level_of, seconds=seconds,
             stl=stl, cpu=cpu)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
