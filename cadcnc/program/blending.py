"""A link's corners rounded within a distance (``cadcnc stream --blend MM``; no OCCT).

A link runs in free air between two cuts: retract, rapid across, rapid down, plunge. Each
corner of its polyline (a turn of the tangent between two of its moves) would stop the
machine at rest. :func:`round_link` replaces each inner corner by a curve tangent- and
curvature-continuous with both legs: a quintic Bezier whose six control points lie on
the two legs within ``d`` of the corner (three on each, so its curvature is zero where it
meets them). By the convex-hull property the curve stays inside the triangle of the
corner and the legs' points at ``d``: within ``d`` of the original polyline. The link's
first and last points (where it meets a cut) are never moved, and cuts are never rounded.

``d`` is the blend asked for, at most BLEND_SHARE of each leg it shortens (a leg rounded at
both ends keeps a straight middle). Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .program import LinkSegment

BLEND_SHARE = 0.4     # a blend takes at most this share of each leg it shortens
MIN_BLEND = 0.01      # mm: a corner whose blend would be smaller keeps its exact stop
MIN_TURN = 1e-9       # rad: a smaller turn is no corner (collinear moves pass as they are)
MAX_TURN = math.radians(170.0)   # rad: a sharper turn (a reversal) keeps its exact stop
SAMPLE = 0.05         # mm: the largest chord between a blend's samples
MIN_SAMPLES = 33      # samples of a blend at least (the planner's curvature sees the curve)
SPACING = (1.0, 0.6, 0.4)   # the control points' distances from the corner, share of d
"""Of the quintics whose control points lie on the legs, the one (in steps of 0.1 d) whose
peak curvature and peak curvature change allow the fastest pass."""


@dataclass(frozen=True)
class LinkMove:
    """One move of a rounded link: ``points`` (k, 3) mm, two for a straight move, the
    samples of the curve for a blend; ``rapid`` False: at the feed (a blend is a rapid
    only between two rapids)."""

    points: np.ndarray
    rapid: bool

    @property
    def curved(self) -> bool:
        return len(self.points) > 2


def _bernstein5(t: np.ndarray) -> np.ndarray:
    """(n, 6) the degree-5 Bernstein polynomials at ``t`` (n,)."""
    k = np.arange(6)
    binom = np.array([1.0, 5.0, 10.0, 10.0, 5.0, 1.0])
    return binom * t[:, None] ** k * (1.0 - t[:, None]) ** (5 - k)


def corner_blend(corner: np.ndarray, into: np.ndarray, out: np.ndarray,
                 d: float) -> np.ndarray:
    """(n, 3) samples of the blend of a corner (3,) between the unit directions ``into``
    (along the leg arriving) and ``out`` (along the leg leaving), from ``corner - d into``
    to ``corner + d out``; chords at most SAMPLE, MIN_SAMPLES samples at least."""
    ctrl = np.array([corner - c * d * into for c in SPACING]
                    + [corner + c * d * out for c in SPACING[::-1]])
    n = max(MIN_SAMPLES, math.ceil(2.0 * d / SAMPLE) + 1)   # 2 d: the control polygon's
    return _bernstein5(np.linspace(0.0, 1.0, n)) @ ctrl    # length bounds the curve's


def blend_sizes(points: np.ndarray, mm: float) -> np.ndarray:
    """(M,) per point of a link polyline (M, 3) the blend distance of its corner: ``mm``
    at most BLEND_SHARE of each leg; 0 (an exact stop) at the ends, at a straight pass, at
    a reversal and where the blend would be under MIN_BLEND."""
    d = np.zeros(len(points))
    legs = np.diff(points, axis=0)
    lengths = np.linalg.norm(legs, axis=1)
    for i in range(1, len(points) - 1):
        a, b = lengths[i - 1], lengths[i]
        if a <= 0.0 or b <= 0.0:
            continue
        cos = float(np.dot(legs[i - 1], legs[i]) / (a * b))
        turn = math.acos(min(1.0, max(-1.0, cos)))
        size = min(mm, BLEND_SHARE * a, BLEND_SHARE * b)
        if MIN_TURN < turn <= MAX_TURN and size >= MIN_BLEND:
            d[i] = size
    return d


def round_link(link: LinkSegment, d: np.ndarray) -> list[LinkMove]:
    """The link's moves with each inner corner k rounded within ``d[k]`` mm (module doc;
    e.g. :func:`blend_sizes`; 0: an exact corner): the straight legs shortened, a blend
    between them, in order from the link's first point to its last."""
    pts = np.asarray(link.points, dtype=float)
    moves: list[LinkMove] = []
    start = pts[0]
    for i in range(len(pts) - 1):
        leg = pts[i + 1] - pts[i]
        length = float(np.linalg.norm(leg))
        end = pts[i + 1]
        if d[i + 1] > 0.0:
            end = pts[i + 1] - d[i + 1] * leg / length
        moves.append(LinkMove(np.array([start, end]), bool(link.rapid[i])))
        start = end
        if d[i + 1] > 0.0:
            after = pts[i + 2] - pts[i + 1]
            curve = corner_blend(pts[i + 1], leg / length, after / np.linalg.norm(after),
                                 float(d[i + 1]))
            curve[0] = end   # the leg's end exactly
            moves.append(LinkMove(curve, bool(link.rapid[i] and link.rapid[i + 1])))
            start = curve[-1]
    return moves
