"""A part away from the origin finishes as it does at the origin: each pass's guide square
(centred on its plane's point nearest the origin) is made large enough to hold the part,
so no pass leaves its guide and stops short (they all did before, exit 3, "no cut left")."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.ops.finish.shortcut import finish
from helpers.fixtures import FIXTURES

SHIFTS = [(500.0, 500.0, 0.0), (2000.0, -1500.0, 300.0)]


def _moved(shift, folder) -> cadcnc.Part:
    import cadquery as cq

    shape = cq.importers.importStep(str(FIXTURES / "finish_slab.step"))
    path = folder / "slab.step"
    cq.exporters.export(shape.translate(cq.Vector(*shift)), str(path))
    return cadcnc.load_step(path)


@pytest.mark.slow
@pytest.mark.parametrize("options", [dict(stepover=4.0),
                                     dict(strategy="waterline", stepdown=2.0)],
                         ids=["raster", "waterline"])
def test_a_part_far_from_the_origin_gets_the_same_cuts(options, tmp_path):
    here = finish(cadcnc.load_step(FIXTURES / "finish_slab.step"), [5], radius=3.0, **options)
    for k, shift in enumerate(SHIFTS):
        folder = tmp_path / str(k)
        folder.mkdir()
        there = finish(_moved(shift, folder), [5], radius=3.0, **options)
        assert len(there.cuts) == len(here.cuts) > 0
        for a, b in zip(here.cuts, there.cuts):
            assert len(a.path.points) == len(b.path.points)
            assert np.abs(b.path.points - np.asarray(shift) - a.path.points).max() < 1e-6
