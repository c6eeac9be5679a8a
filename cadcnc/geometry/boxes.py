"""OCCT's optimal bounding boxes of shapes, each computed once.

``BRepBndLib.AddOptimal`` costs about 30 ms a free-form face, and the gate asks for the
boxes of the faces near every cut it checks (a new probe per cut): the boxes of a shape's
own geometry (not its triangulation, which may be added later) are kept per shape, found
by OCCT's hash and ``IsEqual`` (the same TShape, location and orientation: the same
geometry). Lengths mm.
"""

from __future__ import annotations

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib

MAX_KEPT = 20_000
"""Boxes kept at most (a batch of many parts): all are dropped beyond it."""
_KEPT: dict[int, list] = {}   # OCCT hash -> [(shape, lo, hi)]
_count = [0]


def optimal_box(shape, use_triangulation: bool) -> tuple[np.ndarray, np.ndarray]:
    """(lo (3,), hi (3,)) of OCCT's optimal axis-aligned bounding box of a shape, mm (of
    its geometry: computed once per shape; of its triangulation: every time)."""
    if use_triangulation:
        return _box(shape, True)
    key = hash(shape)
    for kept, lo, hi in _KEPT.get(key, ()):
        if kept.IsEqual(shape):
            return lo.copy(), hi.copy()
    lo, hi = _box(shape, False)
    if _count[0] >= MAX_KEPT:
        _KEPT.clear()
        _count[0] = 0
    _KEPT.setdefault(key, []).append((shape, lo.copy(), hi.copy()))
    _count[0] += 1
    return lo, hi


def _box(shape, use_triangulation: bool) -> tuple[np.ndarray, np.ndarray]:
    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape, box, use_triangulation, False)
    xmin, ymin, zmin, xmax, ymax, zmax = box.Get()
    return np.array([xmin, ymin, zmin]), np.array([xmax, ymax, zmax])
