"""The tri-dexel stock: three dexel grids (rays along X, Y and Z) over one box, at one
resolution, and their cutting by a list of moves (:mod:`.dexels`, :mod:`.tool_moves`).

Sizes: the box lo..hi (3,) mm holds ``n[i] = ceil((hi[i] - lo[i]) / res)`` cells along
axis i; the grid along k has ``n[u] * n[v]`` rays. Memory and work are estimated before
anything is allocated (:func:`estimate`) and refused over their limits with the figure and
a resolution that fits (:func:`check_limits`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from ..core.work_limits import refuse_over
from .dexels import MAX_COLLISIONS, TILES, bin_moves, cut_tiles, grown
from .sweep_bounds import BOUNDS, bounds_table
from .tool_sweep import CONSTANTS, move_table

K0 = 4                    # intervals a ray holds at first (grown on demand)
BYTES_PER_RAY = 80        # K0 intervals (float32 pairs), counts, extents, initial stock, part crossings
BYTES_PER_MOVE = 8 * (CONSTANTS + BOUNDS)   # a move's constants and bounds (float64 rows)
NS_PER_EVALUATION = 20.0  # ns of one core per ray a move's box covers (benchmarks/simulation: 17)
MAX_MEMORY = 6e9          # bytes one simulation may hold
MAX_SECONDS = 1800.0      # estimated seconds of cutting one simulation may take


@dataclass
class Grid:
    """Rays along axis ``k``: intervals ``iv`` (rays, K, 2) float32 as offsets from
    ``lo[k]``, counts ``cnt`` (rays,) int32; ``nu`` x ``nv`` rays (module doc)."""

    k: int
    lo: np.ndarray
    res: float
    nu: int
    nv: int
    iv: np.ndarray
    cnt: np.ndarray

    @property
    def axes(self) -> tuple[int, int]:
        return (self.k + 1) % 3, (self.k + 2) % 3

    def ray_points(self) -> tuple[np.ndarray, np.ndarray]:
        """(u, v) coordinates (nu,), (nv,) mm of the rays' lines."""
        u, v = self.axes
        return (self.lo[u] + (np.arange(self.nu) + 0.5) * self.res,
                self.lo[v] + (np.arange(self.nv) + 0.5) * self.res)

    def volume(self) -> float:
        """The material's volume, mm^3 (sum of interval lengths times res^2)."""
        n = np.arange(self.iv.shape[1])[None, :] < self.cnt[:, None]
        lengths = (self.iv[:, :, 1].astype(float) - self.iv[:, :, 0]) * n
        return float(lengths.sum() * self.res ** 2)


def cells(lo, hi, res: float) -> np.ndarray:
    """(3,) cells along X, Y, Z of the box lo..hi at ``res``."""
    return np.maximum(np.ceil((np.asarray(hi) - np.asarray(lo)) / res - 1e-9), 1).astype(int)  # round-off: a whole number of cells stays one


def rays(lo, hi, res: float) -> int:
    """Rays of the three grids."""
    n = cells(lo, hi, res)
    return int(n[0] * n[1] + n[1] * n[2] + n[2] * n[0])


def evaluations(lo, hi, res: float, bb_lo: np.ndarray, bb_hi: np.ndarray) -> float:
    """Rays that the moves' boxes (N, 3) cover, summed over the three grids."""
    ext = (np.minimum(bb_hi, hi) - np.maximum(bb_lo, lo)) / res + 1.0
    ext = np.clip(ext, 0.0, None)
    return float((ext[:, 0] * ext[:, 1] + ext[:, 1] * ext[:, 2] + ext[:, 2] * ext[:, 0]).sum())


def estimate(lo, hi, res: float, bb_lo, bb_hi, threads: int) -> tuple[float, float]:
    """(bytes, seconds) the simulation is about to need."""
    return (rays(lo, hi, res) * BYTES_PER_RAY + len(bb_lo) * BYTES_PER_MOVE,
            evaluations(lo, hi, res, bb_lo, bb_hi) * NS_PER_EVALUATION * 1e-9 / max(threads, 1))  # ns to s


def check_limits(lo, hi, res: float, bb_lo, bb_hi, threads: int,
                 max_memory: float = MAX_MEMORY, max_seconds: float = MAX_SECONDS) -> None:
    """WorkLimitError (exit 2) naming the estimate and a resolution that fits."""
    memory, seconds = estimate(lo, hi, res, bb_lo, bb_hi, threads)
    # both scale about as 1 / res^2: the resolution that fits, rounded up to 2 digits
    fit = res * math.sqrt(max(memory / max_memory, seconds / max_seconds, 1.0)) * 1.05
    nice = float(f"{fit:.2g}")
    nice = nice if nice >= fit else float(f"{fit * 1.1:.2g}")
    refuse_over(f"the stock at --resolution {res:g} mm ({rays(lo, hi, res):.3g} rays)",
                memory / 1e9, max_memory / 1e9, "GB",
                f"give --resolution {nice:g} or coarser (limit {max_memory / 1e9:g} GB)")
    refuse_over(f"the simulation at --resolution {res:g} mm", seconds, max_seconds,
                "s of cutting", f"give --resolution {nice:g} or coarser, or more --jobs")


def box_grids(lo, hi, res: float) -> tuple[list[Grid], list[tuple[np.ndarray, np.ndarray]]]:
    """The three grids of the full box, and their initial stock ((rays, 1, 2), (rays,))."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    n = cells(lo, hi, res)
    grids, inits = [], []
    for k in range(3):
        u, v = (k + 1) % 3, (k + 2) % 3
        nr = int(n[u] * n[v])
        init = np.empty((nr, 1, 2), np.float32)
        init[:, 0, 0], init[:, 0, 1] = 0.0, hi[k] - lo[k]
        grids.append(Grid(k, lo, res, int(n[u]), int(n[v]),
                          np.zeros((nr, K0, 2), np.float32), np.zeros(nr, np.int32)))
        inits.append((init, np.ones(nr, np.int32)))
    return grids, inits


def dealt(tiles: np.ndarray, work: np.ndarray) -> np.ndarray:
    """``tiles`` (T,) reordered for prange's split into one contiguous block per thread
    (numba's static schedule: ``parallel_chunksize`` did not apply here, one thread got
    every tile with moves): sorted by ``work`` (T,), longest first, then dealt out
    round-robin, so that each block holds an equal share of long and short tiles."""
    threads = numba.get_num_threads()
    order = tiles[np.argsort(-work, kind="stable")]
    return np.concatenate([order[j::threads] for j in range(threads)])


def cut(grid: Grid, init: tuple[np.ndarray, np.ndarray], moves,
        max_memory: float = MAX_MEMORY) -> list[tuple[int, np.ndarray]]:
    """Cut ``grid`` by ``moves`` (a :class:`~.moves.Moves`) from its initial stock, growing
    K where a ray needs it (refused past ``max_memory`` bytes); the rapids through
    material: [(move, point (3,))]."""
    tile = TILES[grid.k]
    start, order, rng = bin_moves(grid.k, grid.lo, grid.res, grid.nu, grid.nv,
                                  moves.bb_lo, moves.bb_hi, tile)
    ntiles = len(start) - 1
    tiles = dealt(np.arange(ntiles), np.diff(start))
    resume = start[:-1].copy()
    col_move = np.zeros((ntiles, MAX_COLLISIONS), np.int64)
    col_at = np.zeros((ntiles, MAX_COLLISIONS, 3))
    col_n = np.zeros(ntiles, np.int64)
    init_iv, init_cnt = init
    ext = np.empty((len(grid.cnt), 2), np.float32)
    ext[:, 0], ext[:, 1] = 1.0, -1.0
    if grid.iv.shape[1] < init_iv.shape[1]:
        grid.iv = np.zeros((len(grid.cnt), init_iv.shape[1], 2), np.float32)
    table = move_table(moves.p0, moves.p1, moves.axis, moves.radius, moves.length)
    bounds = bounds_table(grid.k, grid.lo[grid.k], table)
    while len(tiles):
        cut_tiles(grid.k, grid.lo, grid.res, grid.nu, grid.nv, tiles, start, order, rng,
                  moves.p0, moves.p1, table, bounds, moves.rapid, moves.bb_lo, moves.bb_hi,
                  init_iv, init_cnt, grid.iv, grid.cnt, ext, resume, col_move, col_at,
                  col_n, tile)
        tiles = np.flatnonzero(resume >= 0)      # resumed where they stopped, K doubled
        tiles = dealt(tiles, start[tiles + 1] - resume[tiles])
        if len(tiles):
            need = len(grid.cnt) * 2 * grid.iv.shape[1] * 8.0
            refuse_over(f"the grid along {'XYZ'[grid.k]} at --resolution {grid.res:g} mm "
                        f"({2 * grid.iv.shape[1]} pieces of material on a ray)", need / 1e9,
                        max_memory / 1e9, "GB", "give a coarser --resolution (memory goes "
                        "as its inverse square)")
            grid.iv = grown(grid.iv, 2 * grid.iv.shape[1])
    return [(int(col_move[t, c]), col_at[t, c].copy())
            for t in range(ntiles) for c in range(col_n[t])]


__all__ = ["Grid", "TILES", "box_grids", "check_limits", "cut", "estimate", "rays"]
