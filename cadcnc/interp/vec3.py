"""3-vectors as plain float tuples for the per-cycle hot path.

numpy pays microseconds of overhead per call on length-3 arrays; a cycle does about a
hundred such operations, so the interpolator's inner loop uses these instead.
"""

from __future__ import annotations

import math

Vec = tuple[float, float, float]


def add(a: Vec, b: Vec) -> Vec:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a: Vec, b: Vec) -> Vec:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(a: Vec, s: float) -> Vec:
    return (a[0] * s, a[1] * s, a[2] * s)


def axpy(s: float, a: Vec, b: Vec) -> Vec:
    """s * a + b."""
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


def dot(a: Vec, b: Vec) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Vec, b: Vec) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


SINGULAR_DET = 1e-14
"""Relative: a 3x3 determinant below this times the rows' norms' product is singular
(round-off of unit-scale rows); the kernel mirrors it (kernel/cycle_math.py)."""


def norm(a: Vec) -> float:
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def solve3(r0: Vec, r1: Vec, r2: Vec, b: Vec) -> Vec | None:
    """Solve the 3x3 system with rows r0, r1, r2 and right side b (Cramer); None if singular."""
    c12 = cross(r1, r2)
    det = dot(r0, c12)
    scale_ = norm(r0) * norm(r1) * norm(r2)
    if abs(det) <= SINGULAR_DET * scale_:
        return None
    c20 = cross(r2, r0)
    c01 = cross(r0, r1)
    # x = (b0 c12 + b1 c20 + b2 c01) / det  (rows of the inverse transposed)
    inv = 1.0 / det
    return (
        (b[0] * c12[0] + b[1] * c20[0] + b[2] * c01[0]) * inv,
        (b[0] * c12[1] + b[1] * c20[1] + b[2] * c01[1]) * inv,
        (b[0] * c12[2] + b[1] * c20[2] + b[2] * c01[2]) * inv,
    )
