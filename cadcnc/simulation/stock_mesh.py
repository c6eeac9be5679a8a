"""The simulated stock as a triangle mesh, from its dexels: the top of the material along
every Z ray (a height field, what a 3-axis program leaves seen from above), every
``stride``-th ray so that the mesh stays at most about ``MAX_SIDE`` x ``MAX_SIDE`` points."""

from __future__ import annotations

import numpy as np

MAX_SIDE = 400


def height_field_mesh(stock) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) mm, triangles (m, 3) int) of ``stock``'s top surface (a
    :class:`~.stock.Stock`); rays without material leave holes."""
    g = stock.grids[2]
    xs, ys = g.ray_points()
    top = stock.heights()
    stride = max(1, int(np.ceil(max(len(xs), len(ys)) / MAX_SIDE)))
    xs, ys, top = xs[::stride], ys[::stride], top[::stride, ::stride]
    nx, ny = len(xs), len(ys)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    verts = np.stack([gx.ravel(), gy.ravel(), np.nan_to_num(top.ravel())], axis=1)
    idx = np.arange(nx * ny).reshape(nx, ny)
    a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    tris = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                           np.stack([a, c, d], -1).reshape(-1, 3)])
    ok = np.isfinite(top.ravel())
    tris = tris[ok[tris].all(axis=1)]
    return verts, tris
