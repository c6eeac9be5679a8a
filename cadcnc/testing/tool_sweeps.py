"""The tool swept along a straight move, measured by OCCT against a part's faces: the
independent check of links and of entries (not cadcnc's guard or gate).

The tool is the ball of radius R' on a shank of radius R' and length L along +Z. A move of
the ball centre from a to b sweeps every point within R' of the parallelogram a, b,
b + L z, a + L z (a segment when the move is vertical or L = 0). The move is clear when
BRepExtrema's distance from that parallelogram to every face of the part (the judge's
faces, :class:`cadcnc.testing.coverage_oracle.Oracle`) is at least R' - TOL. A path
that starts and ends outside the material and crosses it meets a face (distance 0), so
faces alone decide. Lengths mm.
"""

from __future__ import annotations

import math

import numpy as np
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakePolygon,
)
from OCP.gp import gp_Pnt

TOL = 1e-3  # mm: the gouge limit
SIDES = ((1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0))
OUTSIDE = 1.0  # mm beyond R' outside the bounding box where a side approach starts


def _pnt(p) -> gp_Pnt:
    return gp_Pnt(*(float(x) for x in p))


def swept_axis(a, b, shank: float):
    """The shape the tool's axis sweeps moving its ball centre from a to b (see module)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    up = np.array([0.0, 0.0, shank])
    if math.hypot(*(b[:2] - a[:2])) < 1e-9:   # mm: a vertical move
        lo, hi = (a, b) if a[2] <= b[2] else (b, a)
        hi = hi + up
        if np.linalg.norm(hi - lo) < 1e-9:   # mm: no segment
            hi = lo + np.array([0.0, 0.0, 1e-6])   # mm: a segment OCCT can build
        return BRepBuilderAPI_MakeEdge(_pnt(lo), _pnt(hi)).Edge()
    if shank <= 0.0:
        return BRepBuilderAPI_MakeEdge(_pnt(a), _pnt(b)).Edge()
    poly = BRepBuilderAPI_MakePolygon()
    for p in (a, b, b + up, a + up):
        poly.Add(_pnt(p))
    poly.Close()
    return BRepBuilderAPI_MakeFace(poly.Wire(), True).Face()


def move_clearance(oracle, a, b, offset: float, shank: float) -> tuple[float, int]:
    """(distance, face) from the axis swept a -> b to the nearest face of the part (inf, 0
    when none comes within R' + 1)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    pts = np.array([a, b, a + (0, 0, shank), b + (0, 0, shank)])
    return oracle.nearest(swept_axis(a, b, shank), pts.min(axis=0), pts.max(axis=0),
                          offset + 1.0)


def link_moves(program: dict) -> list[tuple[np.ndarray, np.ndarray]]:
    """Every move (a, b) of the links of a program JSON (version 2)."""
    out = []
    for seg in program["segments"]:
        if seg["kind"] == "link":
            pts = np.asarray(seg["points"], float)
            out += [(pts[k], pts[k + 1]) for k in range(len(pts) - 1)]
    return out


def links_check(oracle, program: dict, offset: float, shank: float) -> dict:
    """{"moves", "worst_mm" (how far the worst link move comes nearer than R', <= 0 when
    clear), "face", "bad" (moves nearer than R' - TOL)}."""
    worst, face, bad = -math.inf, 0, 0
    moves = link_moves(program)
    for a, b in moves:
        d, n = move_clearance(oracle, a, b, offset, shank)
        if offset - d > worst:
            worst, face = offset - d, n
        bad += d < offset - TOL
    return {"moves": len(moves), "worst_mm": worst, "face": face, "bad": bad}


def entries_at(oracle, p, offset: float, shank: float, z_safe: float) -> dict:
    """The clearance of every entry onto ball centre ``p``: {"plunge": (d, face) of the
    ball and a shank from p up past z_safe, "side +X" ...: (d, face) of the horizontal
    approach from outside the bounding box at p's height and of the descent there}."""
    p = np.asarray(p, float)
    lo, hi = oracle.boxes[:, :3].min(axis=0), oracle.boxes[:, 3:].max(axis=0)
    out = {"plunge": move_clearance(oracle, p, p, offset, max(z_safe - p[2], 0.0) + shank)}
    for (dx, dy), name in zip(SIDES, ("+X", "-X", "+Y", "-Y")):
        k = 0 if dx else 1
        q = p.copy()
        q[k] = (hi[k] if (dx or dy) > 0 else lo[k]) + (dx or dy) * (offset + OUTSIDE)
        top = np.array([q[0], q[1], max(z_safe, q[2])])
        out[f"side {name}"] = min(move_clearance(oracle, q, p, offset, shank),
                                  move_clearance(oracle, top, q, offset, shank))
    return out


def entry_exists(entries: dict, offset: float) -> bool:
    """Whether one of :func:`entries_at`'s ways is clear (R' - TOL)."""
    return any(d >= offset - TOL for d, _ in entries.values())
