"""Programs and toolpaths compared as the tests compare them."""

from __future__ import annotations

from dataclasses import fields

import numpy as np

from cadcnc.interp.error_bounds import SurfaceBounds
from cadcnc.io import ARRAYS


def commanded(prog) -> np.ndarray:
    """(M, 3) the program's positions in order, each joint once (a segment starts where the
    last ended)."""
    return np.vstack([prog.segments[0].points[:1]] + [s.points[1:] for s in prog.segments])


def assert_same_path(a, b) -> None:
    """Two Toolpaths are the same: every per-point array, offsets, faces, stop, job, bounds."""
    for name in ARRAYS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.offsets == b.offsets and a.faces == b.faces
    assert (a.stop_reason, a.stop_detail) == (b.stop_reason, b.stop_detail)
    assert a.job == b.job
    for ba, bb in zip(a.bounds, b.bounds):
        for f in fields(SurfaceBounds):
            np.testing.assert_array_equal(getattr(ba, f.name), getattr(bb, f.name))


def pencil_run(part, *, radius, faces=None, side="climb", feed=1500.0, axis="+Z", **options):
    """The pencil program of ``part`` (a Part, Workplane or Shape) with a ball of
    ``radius`` mm: ``cadcnc.run`` of a Pencil job (feed mm/min, period 4 ms)."""
    import cadcnc

    if not isinstance(part, cadcnc.Part):
        part = cadcnc.Part.from_cadquery(part)
    job = cadcnc.Job(cadcnc.Tool(radius), feed, 0.004, cadcnc.Pencil(faces, side),
                     source=part.source, axis=axis)
    return cadcnc.run(part, job, **options)
