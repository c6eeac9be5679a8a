"""The cutting kernel's shortcuts change no bit of the stock: the skip of rays a move cannot
cut (:mod:`cadcnc.simulation.sweep_bounds`) and the resumption of a tile whose rays
outgrew K (:func:`cadcnc.simulation.grid.cut`), on random programs with tilted tool axes,
rapids through the stock and rays that need many intervals."""

from __future__ import annotations

import numpy as np

import cadcnc.simulation.grid as grid_module
from cadcnc.simulation.stock import cut_stock
from cadcnc.simulation.sweep_bounds import BOUNDS, KHI, KLO, MISS
from cadcnc.simulation.tool_moves import Run

LO, HI, RES = np.array([0.0, 0.0, 0.0]), np.array([8.0, 6.0, 4.0]), 0.1


def never_skip(k, lo_k, table):
    """A bounds table that skips no ray (no direction, infinite extent)."""
    out = np.zeros((len(table), BOUNDS))
    out[:, KLO], out[:, KHI], out[:, MISS] = -np.inf, np.inf, np.inf
    return out


def programs(seed: int) -> list[Run]:
    """A zigzag of tight passes (many scallop ridges on the rays across them) under +Z, and
    a random walk with rapids under a tilted axis."""
    rng = np.random.default_rng(seed)
    pts = []
    for i, y in enumerate(np.arange(0.5, 5.5, 0.3)):
        xs = np.linspace(-1, 9, 25)[:: 1 if i % 2 == 0 else -1]
        pts.append(np.stack([xs, np.full(25, y), 2.5 + 0.3 * np.sin(xs + y)], 1))
    zig = np.concatenate(pts)
    axis = rng.normal(size=3) + (0, 0, 3)
    walk = np.cumsum(rng.uniform(-1.5, 1.5, (40, 3)), 0) + (4, 3, 2)
    return [Run(zig, np.zeros(len(zig) - 1, bool), 0.8, np.array([0.0, 0.0, 1.0]), 6.0),
            Run(walk, rng.random(39) < 0.3, 0.5, axis / np.linalg.norm(axis), 5.0)]


def state(stock) -> list[bytes]:
    """Each grid's counts and its rays' intervals (unused slots ignored), as bytes."""
    out = []
    for g in stock.grids:
        used = np.arange(g.iv.shape[1])[None, :, None] < g.cnt[:, None, None]
        out += [g.cnt.tobytes(), np.where(used, g.iv, 0)[:, :g.cnt.max()].tobytes()]
    out += [np.array([c.move for c in stock.collisions]).tobytes()]
    out += [np.array([c.at for c in stock.collisions]).tobytes()]
    return out


def test_skipping_rays_and_resuming_tiles_change_no_bit(monkeypatch):
    for seed in (1, 2):
        runs = programs(seed)
        fast = cut_stock(LO, HI, RES, runs, jobs=1)
        assert max(g.iv.shape[1] for g in fast.grids) > grid_module.K0   # K grew: resumed
        assert fast.collisions                                           # rapids met stock
        with monkeypatch.context() as m:
            m.setattr(grid_module, "bounds_table", never_skip)
            m.setattr(grid_module, "K0", 64)          # room from the start: no resumption
            plain = cut_stock(LO, HI, RES, runs, jobs=1)
        assert max(g.iv.shape[1] for g in plain.grids) == 64
        assert state(fast) == state(plain)
