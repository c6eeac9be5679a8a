"""``cadcnc.simulate(part, programs, ...)``: the stock cut by every move of every program,
compared with the part face by face (docs/simulate.md).

Steps: the stock (the part's box grown by a margin, the part offset, or a STEP solid) as
three dexel grids; every program's moves cut in order (:mod:`.stock`); the part's mesh
met by the same rays (:mod:`.part_rays`) and the stock measured at each crossing
(:mod:`.compare`); the suspected gouges measured again by OCCT's exact distance
(:mod:`cadcnc.verification.stock_part`); the report (:mod:`.stock_report`).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from ..core.errors import InputError
from ..geometry.part import Part
from ..io.gcode_reader import gcode_moves
from ..io.program_json import read_program_and_setup
from ..program.program import Program
from ..verification.stock_part import PartDistance, offset_triangles, part_triangles, step_triangles
from .compare import joined, sample_grid
from .grid import cells
from .part_rays import crossings, solid_intervals
from .stock import cut_stock
from .stock_report import SimulationReport, build_report
from .tool_moves import Run, run_of_gcode, run_of_program

MARGIN = 1.0          # mm: the default stock box grows the part's box by this on every side
RESOLUTION = 0.1      # mm: the default ray spacing
MESH_SHARE = 0.5      # the part's mesh deflection as a share of the gouge limit
DEFAULT_THRESHOLD = 0.01   # mm: material left counted when no scallop target is known
GCODE_SUFFIXES = (".ngc", ".nc", ".gcode", ".tap", ".cnc")


def read_runs(programs, radius: float | None = None, tool_tip: bool = False,
              shank: float | None = None) -> list[Run]:
    """Each of ``programs`` as a :class:`~.moves.Run`: a :class:`Program` (+Z or its job's
    axis, part coordinates), a (Program, Setup) pair, a Run, a program JSON path, or a
    G-code path (read by rs274 with the ball ``radius``)."""
    runs = []
    for i, p in enumerate(programs, 1):
        if isinstance(p, Run):
            runs.append(p)
        elif isinstance(p, Program):
            runs.append(run_of_program(p, None, shank, f"program {i}"))
        elif isinstance(p, tuple) and len(p) == 2 and isinstance(p[0], Program):
            runs.append(run_of_program(p[0], p[1], shank, f"program {i}"))
        elif isinstance(p, (str, os.PathLike)):
            path = Path(p)
            if path.suffix.lower() in GCODE_SUFFIXES:
                if radius is None:
                    raise InputError(f"{path}: G-code needs the ball radius (--radius MM)")
                pts, rapid = gcode_moves(path)
                runs.append(run_of_gcode(pts, rapid, radius, tool_tip, shank, str(path)))
            else:
                program, setup = read_program_and_setup(path)
                runs.append(run_of_program(program, setup, shank, str(path)))
        else:
            raise InputError(f"program {i} must be a Program, a (Program, Setup) pair or a "
                             f"file path, got {type(p).__name__}")
    if not runs:
        raise InputError("give at least one program to simulate")
    return runs


def _stock(part: Part, stock, res: float, deflection: float):
    """(lo, hi, initial grids or None, description) of the stock."""
    lo, hi = part.bounding_box()
    if stock is None or stock == "box":
        return lo - MARGIN, hi + MARGIN, None, {"kind": "box", "margin_mm": MARGIN}
    if isinstance(stock, (int, float)) and not isinstance(stock, bool):
        if not stock >= 0:
            raise InputError(f"the stock offset must be >= 0 mm, got {stock}")
        tris, _ = offset_triangles(part, float(stock), deflection)
        desc = {"kind": "offset", "offset_mm": float(stock)}
    elif isinstance(stock, tuple) and stock[0] == "box":
        m = float(stock[1])
        if not m >= 0:
            raise InputError(f"the stock margin must be >= 0 mm, got {m}")
        return lo - m, hi + m, None, {"kind": "box", "margin_mm": m}
    else:
        tris, _ = step_triangles(stock, deflection)
        desc = {"kind": "step", "file": str(stock)}
    pad = 2 * res
    return tris.reshape(-1, 3).min(axis=0) - pad, tris.reshape(-1, 3).max(axis=0) + pad, \
        tris, desc


def simulate(part: Part, programs, *, stock="box", resolution: float = RESOLUTION,
             jobs: int | None = None, radius: float | None = None, tool_tip: bool = False,
             shank: float | None = None, threshold: float | None = None,
             limits: dict | None = None) -> SimulationReport:
    """Simulate ``programs`` (see :func:`read_runs`) on ``part``'s stock.

    ``stock``: "box" (the part's box grown by 1 mm), ("box", MARGIN), an offset in mm (a
    number), or a STEP file's path; ``resolution``: the rays' spacing (mm); ``jobs``:
    threads (None: every core); ``radius``/``tool_tip``: for G-code; ``shank``: mm of
    shank above the ball centre (None: a cadcnc program's own tool's, a G-code program's up
    to its highest point); ``threshold``: the
    material left counted in ``area_over_mm2`` (None: the finish jobs' scallop, else 0.01
    mm). The report's ``exit_code`` is 5 on a gouge or a collision."""
    if not (isinstance(resolution, (int, float)) and resolution > 0):
        raise InputError(f"resolution must be > 0 mm, got {resolution!r}")
    runs = read_runs(programs, radius, tool_tip, shank)
    lam = part.tol.gouge
    deflection = max(MESH_SHARE * lam, 1e-5)  # mm: a finer mesh than 10 nm is OCCT's noise
    lo, hi, solid, desc = _stock(part, stock, resolution, deflection)
    clock = time.perf_counter()
    initial = None
    if solid is not None:
        initial = []
        n = cells(lo, hi, resolution)
        for k in range(3):
            u, v = (k + 1) % 3, (k + 2) % 3
            start, t, *_ = crossings(k, lo, resolution, n[u], n[v], solid,
                                     np.zeros(len(solid), np.int32))
            initial.append(solid_intervals(start, t))
    stock_state = cut_stock(lo, hi, resolution, runs, jobs, initial, limits)
    cut_s = time.perf_counter() - clock
    clock = time.perf_counter()
    tris, faces = part_triangles(part, deflection)
    samples = joined([sample_grid(g, crossings(g.k, g.lo, g.res, g.nu, g.nv, tris, faces))
                      for g in stock_state.grids])
    report = build_report(part, runs, stock_state, samples, desc, PartDistance(part), lam,
                          deflection, threshold if threshold is not None else
                          _scallop(runs))
    report.timing = {"cut_s": cut_s, "compare_s": time.perf_counter() - clock}
    return report


def _scallop(runs: list[Run]) -> float:
    """The finish jobs' smallest scallop target (mm), else 0.01."""
    targets = [r.scallop for r in runs if r.scallop]
    return min(targets) if targets else DEFAULT_THRESHOLD
