"""A link's corners rounded (cadcnc.program.blending), judged by the geometry alone: each
blend within its distance of the polyline, tangent to both legs with zero curvature where
it meets them, the link's ends kept, and the corners it must not round left exact."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cadcnc.program.blending import BLEND_SHARE, blend_sizes, corner_blend, round_link
from cadcnc.program.program import LinkSegment

LINK = LinkSegment(np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 30.0], [40.0, 10.0, 30.0],
                             [40.0, 10.0, 5.0], [40.0, 10.0, 2.0]]),
                   [True, True, True, False])


def _to_polyline(x: np.ndarray, poly: np.ndarray) -> np.ndarray:
    a, b = poly[:-1], poly[1:]
    ab = b - a
    t = np.einsum("nmk,mk->nm", x[:, None] - a[None], ab) / np.einsum("mk,mk->m", ab, ab)
    near = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    return np.linalg.norm(x[:, None] - near, axis=2).min(axis=1)


def _curvature(p: np.ndarray) -> np.ndarray:
    a, b, c = p[1:-1] - p[:-2], p[2:] - p[1:-1], p[2:] - p[:-2]
    return 2.0 * np.linalg.norm(np.cross(a, b), axis=1) / (
        np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1) * np.linalg.norm(c, axis=1))


@pytest.mark.parametrize("mm", [0.5, 5.0, 100.0])
def test_each_blend_stays_within_its_distance_and_the_ends_are_kept(mm):
    moves = round_link(LINK, blend_sizes(LINK.points, mm))
    pts = np.vstack([m.points for m in moves])
    assert _to_polyline(pts, LINK.points).max() <= mm + 1e-9
    np.testing.assert_array_equal(moves[0].points[0], LINK.points[0])
    np.testing.assert_array_equal(moves[-1].points[-1], LINK.points[-1])
    for a, b in zip(moves[:-1], moves[1:]):   # no gap between moves
        np.testing.assert_array_equal(a.points[-1], b.points[0])


def test_blends_are_tangent_with_zero_curvature_at_the_legs():
    into, out = np.array([0.0, 0.0, 1.0]), np.array([0.6, 0.8, 0.0])
    curve = corner_blend(np.zeros(3), into, out, 2.0)
    t0, t1 = curve[1] - curve[0], curve[-1] - curve[-2]
    assert np.linalg.norm(np.cross(t0 / np.linalg.norm(t0), into)) < 1e-3
    assert np.linalg.norm(np.cross(t1 / np.linalg.norm(t1), out)) < 1e-3
    k = _curvature(curve)   # at the inner samples: extrapolated onto the ends, zero
    assert abs(2.0 * k[0] - k[1]) < 0.01 * k.max()
    assert abs(2.0 * k[-1] - k[-2]) < 0.01 * k.max()


def test_sizes_share_the_legs_and_skip_straight_and_reversed_corners():
    pts = np.array([[0.0, 0, 0], [0, 0, 10], [0, 0, 20], [4, 0, 20], [4, 0, 19.99],
                    [4, 0, 30]])
    d = blend_sizes(pts, 20.0)
    assert d[0] == d[-1] == 0.0
    assert d[1] == 0.0                                  # collinear: no corner
    assert math.isclose(d[2], BLEND_SHARE * 4.0)        # the shorter leg's share
    assert d[3] == 0.0                                  # its blend would be under 0.01 mm
    assert d[4] == 0.0                                  # a reversal keeps its stop


def test_a_blend_between_a_rapid_and_a_feed_move_is_at_the_feed():
    link = LinkSegment(np.array([[0.0, 0, 0], [0, 0, 10], [10, 0, 10]]), [True, False])
    moves = round_link(link, blend_sizes(link.points, 2.0))
    assert [m.rapid for m in moves] == [True, False, False]
    assert moves[1].curved
