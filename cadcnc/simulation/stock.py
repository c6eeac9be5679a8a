"""The stock cut by programs: three dexel grids and the rapids that went through material.

:func:`cut_stock` is the whole cutting stage on plain arrays (no OCCT): the stock box,
its initial material (the full box, or rays given by :mod:`.part_rays`), the runs, the
resolution, the threads. Limits are checked first (:func:`~.grid.check_limits`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np

from .grid import MAX_MEMORY, Grid, box_grids, check_limits, cut
from .tool_moves import Moves, Run, moves_of_runs


@dataclass
class Collision:
    """A rapid (``move``: its index in the simulation's moves, 0-based; ``run``: its
    program's) whose tool went through material, first met at ``at`` (3,) mm."""

    move: int
    run: int
    at: np.ndarray


@dataclass
class Stock:
    """The cut stock: box lo..hi (3,) mm, resolution mm, grids along X, Y, Z."""

    lo: np.ndarray
    hi: np.ndarray
    res: float
    grids: list[Grid]
    moves: Moves
    collisions: list[Collision] = field(default_factory=list)

    def volume(self) -> float:
        """The material's volume, mm^3, from the Z grid."""
        return self.grids[2].volume()

    def heights(self) -> np.ndarray:
        """(nx, ny) top of the material along each Z ray, mm (NaN: no material)."""
        g = self.grids[2]
        top = np.full(len(g.cnt), np.nan)
        has = g.cnt > 0
        top[has] = g.iv[has, g.cnt[has] - 1, 1] + g.lo[2]
        return top.reshape(g.nu, g.nv)


def cut_stock(lo, hi, res: float, runs: list[Run], jobs: int | None = None,
              initial=None, limits: dict | None = None) -> Stock:
    """The box lo..hi (3,) mm at ``res`` mm cut by every move of ``runs`` in order.
    ``initial``: per grid (iv (rays, K, 2) float32, cnt (rays,)) of the starting material
    (None: the full box); ``jobs``: numba threads (None: every core); ``limits``: keywords
    of :func:`~.grid.check_limits`."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    moves = moves_of_runs(runs, lo, hi)
    threads = numba.config.NUMBA_NUM_THREADS if jobs is None else max(1, min(
        int(jobs), numba.config.NUMBA_NUM_THREADS))
    check_limits(lo, hi, res, moves.bb_lo, moves.bb_hi, threads, **(limits or {}))
    grids, inits = box_grids(lo, hi, res)
    if initial is not None:
        inits = list(initial)
    before = numba.get_num_threads()
    numba.set_num_threads(threads)
    collisions: dict[int, np.ndarray] = {}
    try:
        for g, init in zip(grids, inits):
            for m, at in cut(g, init, moves, (limits or {}).get("max_memory", MAX_MEMORY)):
                v = moves.p1[m] - moves.p0[m]      # keep the point met first along the move
                if m not in collisions or at @ v < collisions[m] @ v:
                    collisions[m] = at
    finally:
        numba.set_num_threads(before)
    found = [Collision(m, int(moves.run[m]), collisions[m]) for m in sorted(collisions)]
    return Stock(lo, hi, res, grids, moves, found)
