"""G-code: digits, point dropping, and LinuxCNC's rs274 reading every generated program."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from cadcnc.io.gcode import DEFAULT_TOLERANCE, digits_for, programmed_points, simplify
from cadcnc.io.program_gcode import to_ngc
from cadcnc.ops.path.pair_path import intersection_paths
from cadcnc.testing.rs274 import DECIMALS as RS274_DECIMALS
from cadcnc.testing.rs274 import feed_points
from helpers.fixtures import fixture_path, load_fixture
from helpers.marks import needs_rs274


@pytest.fixture(scope="module")
def paths():
    saddle = load_fixture("crossing_cylinders")
    return {
        "boss": [fixture_path("bspline_boss", 4, 5)],
        "saddles": intersection_paths(saddle.face(1), saddle.face(2), radius=3.0,
                                             allowance=0.2, feed=1500.0, period=0.004),
    }


@pytest.mark.parametrize("tol, digits", [(1.0, 1), (0.1, 2), (0.01, 3), (0.001, 4),
                                         (1e-4, 5), (2e-3, 4), (8.7e-4, 4)])
def test_digits_rounding_within_a_tenth(tol, digits):
    assert digits_for(tol) == digits
    assert math.sqrt(3) / 2 * 10.0 ** -digits <= tol / 10
    assert math.sqrt(3) / 2 * 10.0 ** -(digits - 1) > tol / 10  # and no more digits


def _segment_distance(p, a, b):
    ab = b - a
    t = np.clip((p - a) @ ab / (ab @ ab), 0, 1) if ab @ ab else 0.0
    return np.linalg.norm(p - (a + t * ab))


@pytest.mark.parametrize("tol", [1e-4, 1e-3, 1e-2])
def test_simplify_moves_the_polyline_less_than_the_tolerance(tol):
    rng = np.random.default_rng(5)
    s = np.linspace(0, 6, 600)
    pts = np.column_stack([10 * np.cos(s), 10 * np.sin(s), s]) + rng.normal(0, tol / 5, (600, 3))
    keep = simplify(pts, tol)
    assert keep[0] == 0 and keep[-1] == len(pts) - 1 and np.all(np.diff(keep) > 0)
    assert len(keep) < len(pts) or tol < 1e-3  # sagitta of a 0.1 mm step on r 10: 1.25e-4
    for a, b in zip(keep[:-1], keep[1:]):
        for k in range(a + 1, b):
            assert _segment_distance(pts[k], pts[a], pts[b]) < tol


def test_simplify_keeps_a_straight_line_ends_only():
    pts = np.column_stack([np.linspace(0, 1, 50)] * 3)
    assert simplify(pts, 1e-9).tolist() == [0, 49]
    assert simplify(pts[:2], 1.0).tolist() == [0, 1]


def test_program_structure(paths):
    text = to_ngc(paths["boss"], spindle=12000)
    lines = text.splitlines()
    assert lines[0] == "%" and lines[-1] == "%" and lines[-2] == "M2"
    assert "G17 G21 G40 G90 G94" in lines and "G64 P0.0001" in lines
    assert "F1500" in lines and "S12000 M3" in lines and "M5" in lines
    n = len(paths["boss"][0])
    assert sum(line.startswith("G1 ") for line in lines) == n  # one G1 per kept point
    assert not re.search(r"\d[eE][+-]?\d", text)  # no exponent notation


@needs_rs274
@pytest.mark.parametrize("which", ["boss", "saddles"])
@pytest.mark.parametrize("tool_tip", [False, True])
def test_rs274_reads_every_point(paths, tmp_path, which, tool_tip):
    tps = paths[which]
    feeds = feed_points(tmp_path, to_ngc(tps, tool_tip=tool_tip))
    expected = np.vstack([programmed_points(tp, tool_tip) for tp in tps])
    # a path starting where the last one ended continues it: the joint is fed once
    joint = np.r_[False, np.linalg.norm(np.diff(expected, axis=0), axis=1) < 1e-9]
    assert joint.sum() == (which == "saddles")
    expected = expected[~joint]
    assert feeds.shape == expected.shape
    half = 0.5 * 10.0 ** -RS274_DECIMALS
    np.testing.assert_allclose(feeds, expected, rtol=0, atol=half + 1e-9)
    if tool_tip:
        centres = np.vstack([tp.points for tp in tps])[~joint]
        np.testing.assert_allclose(feeds[:, 2], centres[:, 2] - 3.0,
                                   rtol=0, atol=half + 1e-9)


@needs_rs274
@pytest.mark.parametrize("tol", [0.001, 0.01])
def test_rs274_reads_dropped_points(paths, tmp_path, tol):
    tp = paths["boss"][0]
    feeds = feed_points(tmp_path, to_ngc([tp], tolerance=tol))
    keep = simplify(tp.points, tol)
    assert len(feeds) == len(keep) < len(tp)
    decimals = digits_for(tol)
    half = 0.5 * 10.0 ** -min(decimals, RS274_DECIMALS)
    np.testing.assert_allclose(feeds, tp.points[keep], rtol=0, atol=half + 1e-9)
    # every computed point lies within tolerance (+ rounding) of the programmed polyline
    worst = max(min(_segment_distance(p, a, b) for a, b in zip(feeds[:-1], feeds[1:]))
                for p in tp.points[::7])
    assert worst < tol + 2 * half


def test_default_tolerance_is_one_micrometre():
    assert DEFAULT_TOLERANCE == 0.001 and digits_for(DEFAULT_TOLERANCE) == 4
