"""The trim grid's third round: segment lists in MIXED cells, the compiled polygon samples.

- ``cadcnc.interp.kernel.trim_lookup.resolve`` takes a labelled neighbour's label only across a clear move, and
  defers (CELL_MIXED) inside a band or when boxed in (a synthetic cell, closed forms).
- The compiled pcurve and surface samples agree with OCCT's evaluation to round-off, and
  the polygon, bands and labels built with them equal the OCCT-only build (fixture faces).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FORWARD
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

import cadcnc
from cadcnc.core.trim_labels import CELL_INSIDE, CELL_MIXED, CELL_OUTSIDE, SEGMENTS
from cadcnc.geometry import fclass_polygon
from cadcnc.geometry.polygon_points import pcurve_points, surface_points
from cadcnc.geometry.surface_data import surface_data
from cadcnc.geometry.trim_grid import TrimGrid, classifier_tolerance
from cadcnc.interp.kernel.trim_lookup import lookup
from cadcnc.interp.tangency import _solve4

FIXTURES = Path(__file__).resolve().parents[2] / "fixtures"
NAMES = ["bspline_boss", "crossing_cylinders", "sphere_cylinder", "torus_cone"]


def one_mixed_cell(segments: list, half: float = 0.01) -> tuple:
    """A 3 x 3 grid of unit cells, INSIDE left of u = 1.5 and OUTSIDE right of it except
    the middle cell, MIXED, holding ``segments`` ((p, q) pairs, half-widths ``half``)."""
    codes = np.array([[CELL_INSIDE] * 3, [CELL_INSIDE, 3, CELL_OUTSIDE],
                      [CELL_OUTSIDE] * 3], dtype=np.int64)
    fine = [SEGMENTS, len(segments), 1e-12, 1e-12]
    for (p, q) in segments:
        fine += [*p, *q, half, half]
    return codes, np.array(fine), 0.0, 0.0, 1.0, 1.0, 3, 3


def test_resolve_crosses_no_band():
    # a band along u = 1.5 through the middle cell (i = 1 along u): left of it the
    # neighbour below (i = 0, INSIDE), right of it the neighbour above (i = 2, OUTSIDE)
    args = one_mixed_cell([((1.5, 1.0), (1.5, 2.0))])
    assert lookup(*args, 1.2, 1.5) == CELL_INSIDE
    assert lookup(*args, 1.8, 1.5) == CELL_OUTSIDE
    assert lookup(*args, 1.505, 1.5) == CELL_MIXED       # inside the band's half-width
    assert lookup(*args, 1.5 + 0.01 + 1e-6, 1.5) == CELL_OUTSIDE   # just clear of it


def test_resolve_defers_when_boxed_in():
    # a closed square of segments around (1.5, 1.5): no move from inside it is clear
    a, b, c, d = (1.3, 1.3), (1.7, 1.3), (1.7, 1.7), (1.3, 1.7)
    args = one_mixed_cell([(a, b), (b, c), (c, d), (d, a)])
    assert lookup(*args, 1.5, 1.5) == CELL_MIXED
    assert lookup(*args, 1.1, 1.5) == CELL_INSIDE         # left of the square: move to i - 1
    assert lookup(*args, 1.9, 1.5) == CELL_OUTSIDE        # right of it: only i + 1 is clear


def edges_of(face):
    """(BRepAdaptor_Curve2d, BRepAdaptor_Curve) of each edge of a FaceSurface."""
    topo = TopoDS.Face_s(face.topods.Oriented(TopAbs_FORWARD))
    explorer, out = TopExp_Explorer(topo, TopAbs_EDGE), []
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        out.append((BRepAdaptor_Curve2d(edge, topo), BRepAdaptor_Curve(edge, topo)))
        explorer.Next()
    return topo, out


@pytest.mark.parametrize("name", NAMES)
def test_compiled_samples_agree_with_occt(name):
    part = cadcnc.load_step(FIXTURES / f"{name}.step")
    checked = 0
    for face in part.faces:
        topo, edges = edges_of(face)
        surface, data = BRepAdaptor_Surface(topo, False), surface_data(face)
        for c2, c3 in edges:
            t = np.linspace(c2.FirstParameter(), c2.LastParameter(), 41)
            uv = pcurve_points(c2, t)
            if uv is None:
                continue
            exact = np.array([c2.Value(x).Coord() for x in t.tolist()])
            assert np.abs(uv - exact).max() <= 1e-12 * (1 + np.abs(exact).max())
            for d in (None, data):
                xyz = surface_points(surface, uv, d)
                if xyz is None:
                    continue
                m = surface.Trsf()
                mat = np.array([[m.Value(i, j) for j in range(1, 5)] for i in range(1, 4)])
                xyz = xyz @ mat[:, :3].T + mat[:, 3]
                ref = np.array([c3.Value(x).Coord() for x in t.tolist()])
                assert np.abs(xyz - ref).max() <= 1e-11 * (1 + np.abs(ref).max()), face
                checked += 1
    assert checked > 0


@pytest.mark.parametrize("name", NAMES)
def test_compiled_polygon_builds_the_occt_grid(name, monkeypatch):
    part = cadcnc.load_step(FIXTURES / f"{name}.step")
    fast = [(fclass_polygon.polygon_bands(f, classifier_tolerance(f), surface_data(f)),
             TrimGrid.build(f, data=surface_data(f))) for f in part.faces]
    monkeypatch.setattr(fclass_polygon, "_FAST_FROM", 10 ** 9)   # OCCT's calls only
    for face, (bands, grid) in zip(part.faces, fast):
        exact = fclass_polygon.polygon_bands(face, classifier_tolerance(face))
        for a, b in zip(bands, exact):
            assert a.shape == b.shape
            assert np.abs(a - b).max(initial=0.0) <= 1e-12 * (1 + np.abs(b).max(initial=0.0))
        ref = TrimGrid.build(face)
        assert np.array_equal(grid.labels, ref.labels) and np.array_equal(grid.codes, ref.codes)


def test_solve4_matches_numpy():
    rng = np.random.default_rng(5)
    for _ in range(50):
        a, b = rng.normal(size=(4, 4)), rng.normal(size=4)
        x = _solve4(a.tolist(), b.tolist())
        assert np.allclose(x, np.linalg.solve(a, b), rtol=1e-10, atol=1e-12)
    singular = [[1.0, 2.0, 0.0, 0.0], [2.0, 4.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0]]
    x = _solve4(singular, [1.0, 2.0, 3.0, 4.0])   # least squares: exact on the consistent
    assert np.allclose(np.array(singular) @ x, [1.0, 2.0, 3.0, 4.0])
