"""The torus's closed form along a segment (geometry/torus_segment.py).

- Its quartic's roots are numpy's own (the same companion matrix and eigenvalues, so the
  guard's programs are the same bytes), and Horner's values numpy's polyval's.
- Along segments of any direction, including ones through the axis (where the quartic
  degenerates), the least distance to the whole torus over 200 001 samples is met within
  the sampling's step at one of ``local_nearest``'s places.
"""

from __future__ import annotations

import math

import numpy as np

from cadcnc.geometry.torus_segment import Torus, _horner, _roots, local_nearest

TORUS = Torus((1.0, -2.0, 3.0), (0.0, math.sin(0.4), math.cos(0.4)), 12.0, 4.0)


def test_roots_and_values_are_numpys():
    rng = np.random.default_rng(3)
    for _ in range(500):
        q = rng.normal(size=5) * 10.0 ** rng.integers(-3, 4, size=5)
        assert np.array_equal(_roots(q), np.roots(q))
        x = float(rng.normal())
        assert _horner(q.tolist(), x) == float(np.polyval(q, x))


def _whole(t: Torus, pts: np.ndarray) -> np.ndarray:
    w = pts - np.asarray(t.o)
    ax = w @ np.asarray(t.z)
    rho = np.linalg.norm(w - np.outer(ax, t.z), axis=1)
    return np.abs(np.hypot(rho - t.major, ax) - t.minor)


def _check(p, d, length: float) -> None:
    s = np.linspace(0.0, length, 200_001)
    dist = _whole(TORUS, np.asarray(p) + np.outer(s, d))
    places = np.asarray(local_nearest(TORUS, tuple(p), length, tuple(d)))
    at = _whole(TORUS, np.asarray(p) + np.outer(places, d))
    step = s[1] - s[0]
    assert at.min() <= dist.min() + 1e-9
    assert at.min() >= dist.min() - step


def test_the_least_distance_is_at_one_of_the_places():
    rng = np.random.default_rng(4)
    for _ in range(40):
        p = np.asarray(TORUS.o) + rng.uniform(-20.0, 20.0, size=3)
        d = rng.normal(size=3)
        _check(p, d / np.linalg.norm(d), 30.0)


def test_segments_through_the_axis():
    z, o = np.asarray(TORUS.z), np.asarray(TORUS.o)
    side = np.cross(z, (1.0, 0.0, 0.0))
    side /= np.linalg.norm(side)
    for h in (-3.0, 0.0, 5.0):   # through the axis at height h, across it
        _check(o + h * z - 15.0 * side, side, 30.0)
