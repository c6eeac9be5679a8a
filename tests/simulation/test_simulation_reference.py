"""The stock against an independent boolean reference (manifold3d: the box minus the hulls
of sphere pairs, one hull per move) on a small program; no code shared with the simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cadcnc.simulation.stock import cut_stock
from cadcnc.simulation.tool_moves import Run

manifold3d = pytest.importorskip("manifold3d")

R, SEGMENTS, RES = 2.0, 128, 0.25
LO, HI = np.array([0.0, 0.0, 0.0]), np.array([20.0, 15.0, 8.0])
PROGRAM = np.array([(-1, 3, 7.5), (8, 4, 6.2), (14, 10, 7.0), (21, 12, 5.5), (12, 13, 8.5),
                    (6, 9, 6.8), (2, 14, 9.5)])


def reference_mesh() -> tuple[np.ndarray, np.ndarray]:
    m = manifold3d.Manifold
    stock = m.cube(tuple(HI - LO)).translate(tuple(LO))
    for a, b in zip(PROGRAM[:-1], PROGRAM[1:]):
        sa = m.sphere(R, SEGMENTS).translate(tuple(a))
        sb = m.sphere(R, SEGMENTS).translate(tuple(b))
        stock = stock - m.batch_hull([sa, sb])
    mesh = stock.to_mesh()
    return np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts)


def top_heights(verts, tris, xs, ys) -> np.ndarray:
    """(nx, ny) highest point of the mesh over each (x, y): every upward triangle over the
    points inside it (a plain loop, the reference's own)."""
    top = np.full((len(xs), len(ys)), np.nan)
    for a, b, c in verts[tris]:
        area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        if area <= 0:        # seen from above: counter-clockwise faces point up
            continue
        i = np.flatnonzero((xs >= min(a[0], b[0], c[0])) & (xs <= max(a[0], b[0], c[0])))
        j = np.flatnonzero((ys >= min(a[1], b[1], c[1])) & (ys <= max(a[1], b[1], c[1])))
        if not len(i) or not len(j):
            continue
        px, py = np.meshgrid(xs[i], ys[j], indexing="ij")
        w0 = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) / area
        w1 = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) / area
        w2 = 1 - w0 - w1
        inside = (w0 >= 0) & (w1 >= 0) & (w2 >= 0)
        z = w0 * a[2] + w1 * b[2] + w2 * c[2]
        sub = top[np.ix_(i, j)]
        top[np.ix_(i, j)] = np.where(inside, np.fmax(sub, z), sub)
    return top


def test_z_rays_match_the_boolean_reference():
    run = Run(PROGRAM.astype(float), np.zeros(len(PROGRAM) - 1, bool), R,
              np.array([0.0, 0.0, 1.0]), 0.0, shank=0.0)   # the ball alone, as the reference
    stock = cut_stock(LO, HI, RES, [run], jobs=1)
    verts, tris = reference_mesh()
    xs, ys = stock.grids[2].ray_points()
    h = stock.heights()
    err = h - top_heights(verts, tris, xs, ys)
    assert np.isfinite(err).all()
    # the reference's spheres are inscribed polyhedra: it removes less, by at most twice an
    # edge's sagitta across a face (a triangle's middle); vertically more on steep walls
    tess = 2 * R * (1 - math.cos(math.pi / SEGMENTS))
    assert err.max() <= 1e-6                      # never more material than the reference
    gx, gy = np.gradient(h, RES)
    flat = np.hypot(gx, gy) < 0.15
    assert flat.sum() > 0.4 * flat.size
    assert -err[flat].min() <= tess               # within its tessellation where flat
    assert -err.min() <= RES + tess               # and within the resolution everywhere
    a, b, c = (verts[tris][:, i] for i in range(3))
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6
    assert stock.volume() == pytest.approx(volume, rel=2e-3)
