"""B-spline numbers read in one OCCT call (cadcnc.geometry.bspline_blob) against OCCT's
own accessors, read pole by pole: every B-spline pcurve (periodic ones also as the
non-periodic copy the trim grid evaluates) and every B-spline surface of the fixtures
must give exactly the same poles, weights and knots; a record that does not match its
handle is refused (None), never half-read."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve2d
from OCP.Geom import Geom_BSplineSurface
from OCP.GeomAbs import GeomAbs_BSplineCurve
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from cadcnc.geometry import bspline_blob
from helpers.fixtures import FIXTURES as FOLDER
from helpers.fixtures import load_fixture

FIXTURES = ["abc_fold.step", "bspline_boss", "crossing_cylinders", "ellipse_pocket"]
"""abc_fold (no sidecar entry, loaded by file) has the rational ones."""


def _seq(seq) -> np.ndarray:
    return np.array([seq.Value(i) for i in range(seq.Lower(), seq.Upper() + 1)])


def pcurves(part):
    for face in part.faces:
        explorer = TopExp_Explorer(face.topods, TopAbs_EDGE)
        while explorer.More():
            edge = TopoDS.Edge_s(explorer.Current())
            explorer.Next()
            if BRep_Tool.CurveOnSurface_s(edge, face.topods, 0.0, 0.0) is None:
                continue
            c2 = BRepAdaptor_Curve2d(edge, face.topods)
            if c2.GetType() == GeomAbs_BSplineCurve:
                bs = c2.BSpline()
                yield bs
                if bs.IsPeriodic():
                    flat = bs.Copy()
                    flat.SetNotPeriodic()
                    yield flat


@pytest.mark.parametrize("name", FIXTURES)
def test_blob_reads_equal_occt_accessors(name):
    import cadcnc

    part = cadcnc.load_step(FOLDER / name) if name.endswith(".step") else load_fixture(name)
    curves = surfaces = 0
    for bs in pcurves(part):
        poles, weights, knots, mults = bspline_blob.curve2d(bs)
        n = bs.NbPoles()
        np.testing.assert_array_equal(poles, [bs.Pole(i).Coord() for i in range(1, n + 1)])
        np.testing.assert_array_equal(weights, [bs.Weight(i) for i in range(1, n + 1)]
                                      if bs.IsRational() else np.zeros(0))
        np.testing.assert_array_equal(knots, _seq(bs.Knots()))
        np.testing.assert_array_equal(mults, _seq(bs.Multiplicities()))
        if not bs.IsPeriodic():
            np.testing.assert_array_equal(np.repeat(knots, mults), _seq(bs.KnotSequence()))
        curves += 1
    for face in part.faces:
        surf = BRep_Tool.Surface_s(face.topods)
        if not isinstance(surf, Geom_BSplineSurface):
            continue
        poles, weights, (uk, um), (vk, vm) = bspline_blob.surface(surf)
        nu, nv = surf.NbUPoles(), surf.NbVPoles()
        np.testing.assert_array_equal(poles, [[surf.Pole(i, j).Coord() for j in range(1, nv + 1)]
                                              for i in range(1, nu + 1)])
        if surf.IsURational() or surf.IsVRational():
            np.testing.assert_array_equal(weights, [[surf.Weight(i, j) for j in range(1, nv + 1)]
                                                    for i in range(1, nu + 1)])
        np.testing.assert_array_equal(uk, _seq(surf.UKnots()))
        np.testing.assert_array_equal(vm, _seq(surf.VMultiplicities()))
        surfaces += 1
    assert curves + surfaces > 0


def test_a_record_that_does_not_match_its_handle_is_refused(monkeypatch):
    part = load_fixture("bspline_boss")
    bs = next(pcurves(part))
    assert bspline_blob.curve2d(bs) is not None
    real = bspline_blob._blob

    def shifted(shape):   # the first pole's x one ulp off
        blob = bytearray(real(shape))
        at = blob.find(b"\nCurve2ds 1\n") + 12 + 13
        x = np.frombuffer(bytes(blob[at:at + 8]), "<f8")[0]
        blob[at:at + 8] = np.array([np.nextafter(x, np.inf)], "<f8").tobytes()
        return bytes(blob)

    monkeypatch.setattr(bspline_blob, "_blob", shifted)
    assert bspline_blob.curve2d(bs) is None
    monkeypatch.setattr(bspline_blob, "_blob", lambda shape: b"not a BRep record")
    assert bspline_blob.curve2d(bs) is None
