"""The tri-dexel stock against closed forms: the swept tool on a ray, raster scallops on a
plane and on a cylinder (rays along Z are exact), a 90 degree corner, a rapid through stock."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cadcnc.simulation.dexels import subtract
from cadcnc.simulation.stock import cut_stock
from cadcnc.simulation.tool_moves import Run
from cadcnc.simulation.tool_sweep import swept_tool

UP = np.array([0.0, 0.0, 1.0])


def run(points, radius, rapid=None, shank=None, top=100.0):
    pts = np.asarray(points, float)
    flags = np.zeros(len(pts) - 1, bool) if rapid is None else np.asarray(rapid, bool)
    return Run(pts, flags, radius, UP, top, shank)


def distance_to_parallelogram(x, p0, v, e):
    """Reference: distance from x (3,) to {p0 + s v + h e : s, h in [0, 1]} (numpy)."""
    a = np.stack([v, e], 1)
    sol = np.linalg.lstsq(a, x - p0, rcond=None)[0]
    best = np.inf
    if np.all((sol >= 0) & (sol <= 1)):
        best = np.linalg.norm(x - p0 - a @ sol)
    for s, d in ((p0, v), (p0 + e, v), (p0, e), (p0 + v, e)):
        t = np.clip(np.dot(x - s, d) / max(np.dot(d, d), 1e-300), 0, 1)
        best = min(best, np.linalg.norm(x - s - t * d))
    return best


def test_swept_tool_is_the_set_within_r_of_the_parallelogram():
    rng = np.random.default_rng(7)
    for _ in range(40):
        p0 = rng.uniform(-3, 3, 3)
        p1 = p0 + rng.uniform(-3, 3, 3)
        ax = rng.normal(size=3)
        ax /= np.linalg.norm(ax)
        length, r, k = rng.uniform(0.5, 5), rng.uniform(0.5, 2), int(rng.integers(3))
        o = rng.uniform(-2, 2, 3)
        o[k] = -20.0
        ta, tb = swept_tool(o[0], o[1], o[2], k, *p0, *p1, *ax, r, length)
        e = np.eye(3)[k]
        for t in (ta, tb):
            if ta < tb:   # the interval's ends lie on the boundary, within 1e-9 mm
                d = distance_to_parallelogram(o + t * e, p0, p1 - p0, ax * length)
                assert abs(d - r) < 1e-9
        mid = distance_to_parallelogram(o + 0.5 * (ta + tb) * e, p0, p1 - p0, ax * length)
        assert (mid <= r + 1e-12) if ta < tb else True


def test_subtract_splits_and_overflows():
    iv = np.zeros((1, 2, 2), np.float32)
    iv[0, 0] = (0.0, 10.0)
    n, overlap, first = subtract(iv, 0, 1, 2.0, 3.0, 2)
    assert n == 2 and overlap == pytest.approx(1.0) and first == pytest.approx(2.0)
    assert iv[0].tolist() == [[0.0, 2.0], [3.0, 10.0]]
    assert subtract(iv, 0, 2, 5.0, 6.0, 2)[0] == -1          # a third piece needs K = 3
    assert subtract(iv, 0, 2, -1.0, 11.0, 2)[0] == 0         # all removed


def raster(stepover, radius, n_pass, x0=-1.0, x1=11.0, z=0.0):
    """Zigzag passes along X at y = k * stepover, ball centre at z + R, joined by feed moves."""
    pts = []
    for k in range(n_pass):
        xs = (x0, x1) if k % 2 == 0 else (x1, x0)
        pts += [(xs[0], k * stepover, z + radius), (xs[1], k * stepover, z + radius)]
    return pts


@pytest.mark.parametrize("stepover", [0.4, 1.0])
def test_plane_scallops_equal_their_closed_form(stepover):
    """Every Z ray's material above the plane z = 0 is R - sqrt(R^2 - d^2), d its distance to
    the nearest pass: the crest at s / 2 is R - sqrt(R^2 - (s/2)^2), within 0.5 um."""
    r, res = 3.0, 0.05
    stock = cut_stock((0, -0.025, -2), (10, 4, 3), res,   # rays at y = s / 2
                      [run(raster(stepover, r, 12), r)], jobs=1)
    g = stock.grids[2]
    xs, ys = g.ray_points()
    top = stock.heights()
    d = np.abs(ys - np.round(ys / stepover) * stepover)
    closed = r - np.sqrt(r * r - d * d)
    inner = (xs > 1) & (xs < 9)
    err = np.abs(top[inner] - closed[None, :])
    assert err.max() < 5e-4
    crest = r - math.sqrt(r * r - (stepover / 2) ** 2)
    assert abs(top[inner].max() - crest) < 5e-4


def test_cylinder_scallop_equals_its_closed_form():
    """Passes along X over a convex cylinder of radius Rc (axis X), at angles +-phi/2: the
    cusp on the Z ray through the axis stands rho - Rc above it, rho = D cos(phi/2) -
    sqrt(R^2 - D^2 sin^2(phi/2)), D = Rc + R; within 0.5 um."""
    rc, r, phi = 10.0, 3.0, math.radians(8.0)
    d = rc + r
    pts = []
    for k, th in enumerate((-phi / 2, phi / 2)):
        y, z = d * math.sin(th), d * math.cos(th)
        pts += [(-1.0, y, z), (6.0, y, z)] if k == 0 else [(6.0, y, z), (-1.0, y, z)]
    res = 0.05   # a Z ray at y = 0: the box from y = -1.025
    stock = cut_stock((0, -1.025, 5), (5, 1, 12), res, [run(pts, r)], jobs=1)
    xs, ys = stock.grids[2].ray_points()
    j = int(np.argmin(np.abs(ys)))
    top = stock.heights()[len(xs) // 2, j] - rc
    rho = d * math.cos(phi / 2) - math.sqrt(r * r - d * d * math.sin(phi / 2) ** 2)
    assert abs(ys[j]) < 1e-12
    assert abs(top - (rho - rc)) < 5e-4


def test_corner_material_equals_its_closed_form():
    """A ball along a sharp 90 degree corner (floor z = 0, wall y = 0) leaves above the
    floor at distance w from the wall R - sqrt(R^2 - (R - w)^2) for w < R: every Z ray and
    every Y ray (the wall) agree within the resolution."""
    r, res = 2.0, 0.05
    pts = [(-1.0, r, r), (6.0, r, r)]
    stock = cut_stock((0, -1, -1), (5, 4, 4), res, [run(pts, r)], jobs=1)
    xs, ys = stock.grids[2].ray_points()
    top = stock.heights()[len(xs) // 2]
    near = (ys > 0) & (ys < r)
    left = np.where(ys[near] < r, r - np.sqrt(r * r - (r - ys[near]) ** 2), 0.0)
    assert np.abs(top[near] - left).max() < res
    gy = stock.grids[1]          # rays along Y (the wall's normal) through (z, x)
    zs, _ = gy.ray_points()
    mid = gy.nv // 2
    first = gy.iv.reshape(gy.nu, gy.nv, -1, 2)[:, mid, 0, 1] + gy.lo[1]   # its end
    above = (zs > 0) & (zs < r)   # material in front of the wall (y = 0) up to z = R
    closed = r - np.sqrt(r * r - (r - zs[above]) ** 2)
    assert np.abs(first[above] - closed).max() < res


def test_a_rapid_through_stock_is_a_collision_and_one_above_is_not():
    r = 1.0
    pts = [(-2, 2, 10), (12, 2, 10), (12, 2, 2), (-2, 2, 2)]
    stock = cut_stock((0, 0, 0), (10, 4, 4), 0.1, [run(pts, r, rapid=[True, True, True])],
                      jobs=1)
    assert [c.move for c in stock.collisions] == [2]
    at = stock.collisions[0].at
    assert abs(at[2] - 2) <= r + 0.1 and 9 <= at[0] <= 10.2
