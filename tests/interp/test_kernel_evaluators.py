"""Compiled surface evaluators (cadcnc.interp.kernel.evaluators) against OCCT's D2.

Every face of every fixture STEP file, and faces built here for the kinds the fixtures
lack (rational, periodic and C1-knotted B-splines, Bezier, extrusions and revolutions of
lines, conics, B-spline and Bezier curves, offsets, located, mirrored and reversed faces),
is sampled at its parameter-box corners and random points; ``d2`` must give OCCT's
r, r_u, r_w, r_uu, r_uw, r_ww (``FaceSurface.derivatives_array``, BRepAdaptor_Surface::D2).

Tolerance, per vector v of the six: |v_kernel - v_occt| <= 1e-12 (size + |v_occt|), size
the bounding-box diagonal (mm). Why this form: r is in mm, but a k-th derivative is in mm
per (parameter unit)^k, so its magnitude follows the parameterisation (a cylinder's r_u is
R mm per radian, a B-spline's r_uu grows like size / (knot span)^2); a fixed tolerance in
mm would be meaningless for it, and |v| alone fails where v is (near) zero. Each evaluation
rounds at about 1e-16 of the largest terms it adds: for r that is the part's extent (size,
whatever |r| is), for a derivative mostly the derivative's own magnitude, size acting as
the floor for vanishing derivatives (r_uw of a cylinder, r_vv of a cone), whose terms are
at most of that order for the parameterisations CAD uses (mm, radians, knots spanning a
patch). 1e-12 is some 5000 units of round-off: room for two different operation orders
(OCCT's span-polynomial cache against de Boor's basis functions) and moderately short
knot spans (the fixtures reach 1e-13). It is not a bound for ill-conditioned spans (spans
thousands of times shorter than the patch, seen on real parts): there both evaluators lose
digits, and benchmarks/kernel/bench_evaluators.py compares each with exact arithmetic.

The (u, w) box corners matter: at a box edge on a C1 knot OCCT evaluates the span inside
the face (LocalD2), and one face here has its box edge on such a knot.
"""

from __future__ import annotations

import math
from pathlib import Path

import numba
import numpy as np
import pytest
from OCP import GeomAbs
from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_NurbsConvert
from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeTorus
from OCP.Geom import (
    Geom_BezierCurve,
    Geom_BezierSurface,
    Geom_BSplineCurve,
    Geom_BSplineSurface,
    Geom_Circle,
    Geom_CylindricalSurface,
    Geom_Ellipse,
    Geom_Hyperbola,
    Geom_Line,
    Geom_OffsetSurface,
    Geom_Parabola,
    Geom_SphericalSurface,
    Geom_SurfaceOfLinearExtrusion,
    Geom_SurfaceOfRevolution,
    Geom_ToroidalSurface,
    Geom_TrimmedCurve,
)
from OCP.gp import gp_Ax1, gp_Ax2, gp_Ax3, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
from OCP.STEPControl import STEPControl_Reader
from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array2OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_Array2OfReal
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedMapOfShape

from cadcnc.geometry.face_surface import FaceSurface
from cadcnc.geometry.surface_data import surface_data
from cadcnc.interp.kernel import evaluators as ev

FIXTURES = sorted((Path(__file__).resolve().parents[2] / "fixtures").glob("*.step"))
SAMPLES = 50
TOL = 1e-12


# -- sampling and comparison --------------------------------------------------------------
def size_of(shape) -> float:
    """Bounding-box diagonal, mm."""
    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box)
    x0, y0, z0, x1, y1, z1 = box.Get()
    return math.dist((x0, y0, z0), (x1, y1, z1))


def uv_samples(fs: FaceSurface, n: int = SAMPLES, seed: int = 0) -> np.ndarray:
    """(n, 2): the four corners of the face's (u, w) box, then random points in it."""
    (u0, u1), (w0, w1) = fs.u_range, fs.w_range
    rng = np.random.default_rng(seed)
    corners = [(u0, w0), (u0, w1), (u1, w0), (u1, w1)]
    return np.vstack([corners, np.c_[rng.uniform(u0, u1, n - 4), rng.uniform(w0, w1, n - 4)]])


def worst_ratio(face, size: float) -> float:
    """max over samples and vectors of |d2 - OCCT| / (TOL (size + |OCCT|)); <= 1 passes."""
    fs = FaceSurface(face)
    data = surface_data(face)
    assert data is not None, fs
    assert data.kind_name == fs.kind
    work, out, ref = ev.new_work(), np.zeros((6, 3)), np.zeros((6, 3))
    worst = 0.0
    for u, w in uv_samples(fs):
        assert ev.d2(*data.args, u, w, work, out) == ev.OK, (fs, u, w)
        fs.derivatives_array(u, w, ref)
        err = np.linalg.norm(out - ref, axis=1) / (TOL * (size + np.linalg.norm(ref, axis=1)))
        worst = max(worst, float(err.max()))
    return worst


def faces_of(shape) -> list:
    fmap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, fmap)
    return [TopoDS.Face_s(fmap.FindKey(i)) for i in range(1, fmap.Extent() + 1)]


def read_step(path: Path):
    reader = STEPControl_Reader()
    reader.ReadFile(str(path))
    reader.TransferRoots()
    return reader.OneShape()


# -- faces the fixtures lack ----------------------------------------------------------------
def reals(values):
    arr = TColStd_Array1OfReal(1, len(values))
    for i, v in enumerate(values):
        arr.SetValue(i + 1, float(v))
    return arr


def counts(values):
    arr = TColStd_Array1OfInteger(1, len(values))
    for i, v in enumerate(values):
        arr.SetValue(i + 1, int(v))
    return arr


def points(pts):
    arr = TColgp_Array1OfPnt(1, len(pts))
    for i, p in enumerate(pts):
        arr.SetValue(i + 1, gp_Pnt(*p))
    return arr


def grid(fn, nu: int, nv: int, cls=TColgp_Array2OfPnt):
    arr = cls(1, nu, 1, nv)
    for i in range(nu):
        for j in range(nv):
            val = fn(i, j)
            arr.SetValue(i + 1, j + 1, gp_Pnt(*val) if cls is TColgp_Array2OfPnt else val)
    return arr


def make_face(surface, *box):
    return BRepBuilderAPI_MakeFace(surface, *box, 1e-7).Face()


def c1_bspline():
    """Rational, degree 3 x 2, a C1 knot (multiplicity 2) at u = 0.4, non-uniform."""
    poles = grid(lambda i, j: (10.0 * i + 0.3 * j * j, 7.0 * j + 0.5 * i,
                               3.0 * math.sin(i + 0.7 * j)), 6, 4)
    weights = grid(lambda i, j: 1.0 + 0.1 * ((3 * i + j) % 4), 6, 4, TColStd_Array2OfReal)
    return Geom_BSplineSurface(poles, weights, reals([0, 0.4, 1]), reals([0, 0.3, 1]),
                               counts([4, 2, 4]), counts([3, 1, 3]), 3, 2, False, False)


def periodic_bspline():
    """Rational, periodic in u (7 poles, degree 3), degree 2 in v."""
    n = 7
    poles = grid(lambda i, j: (15 * math.cos(2 * math.pi * i / n) * (1 + 0.1 * j),
                               15 * math.sin(2 * math.pi * i / n), 8.0 * j + i % 2), n, 4)
    weights = grid(lambda i, j: 1.0 + 0.2 * (i % 3), n, 4, TColStd_Array2OfReal)
    return Geom_BSplineSurface(poles, weights, reals(range(n + 1)), reals([0, 0.5, 1]),
                               counts([1] * (n + 1)), counts([3, 1, 3]), 3, 2, True, False)


def bezier():
    poles = grid(lambda i, j: (5.0 * i, 4.0 * j, math.cos(i) * math.sin(j + 1)), 5, 4)
    weights = grid(lambda i, j: 1.0 + 0.3 * ((i + j) % 3), 5, 4, TColStd_Array2OfReal)
    return Geom_BezierSurface(poles, weights)


def spline_curve():
    return Geom_BSplineCurve(points([(5, 0, 0), (8, 0, 6), (6, 0, 12), (9, 0, 18), (7, 0, 24)]),
                             reals([0, 0.5, 1]), counts([4, 1, 4]), 3, False)


def nurbs_arc():
    """A rational quadratic quarter circle, radius 10."""
    return Geom_BSplineCurve(points([(10, 0, 0), (10, 10, 0), (0, 10, 0)]),
                             reals([1, math.sqrt(0.5), 1]), reals([0, 1]), counts([3, 3]), 2,
                             False)


def basis_curves() -> dict:
    """Basis curves and the parameter range a face on them uses."""
    frame = gp_Ax2(gp_Pnt(1, 2, 3), gp_Dir(0, 0.1, 1))
    return {
        "spline": (spline_curve(), 0.0, 1.0),
        "nurbs arc": (nurbs_arc(), 0.0, 1.0),
        "trimmed spline": (Geom_TrimmedCurve(spline_curve(), 0.2, 0.5), 0.2, 0.5),
        "periodic spline": (Geom_BSplineCurve(
            points([(12 * math.cos(a), 0, 8 * math.sin(a) + 2 * math.cos(3 * a))
                    for a in np.linspace(0, 2 * math.pi, 6, endpoint=False)]),
            reals(range(7)), counts([1] * 7), 3, True), -1.0, 4.5),
        "bezier": (Geom_BezierCurve(points([(0, 0, 0), (3, 5, 0), (7, -2, 1), (10, 0, 0)]),
                                    reals([1, 2, 0.7, 1])), 0.0, 1.0),
        "ellipse": (Geom_Ellipse(frame, 9.0, 4.0), 0.3, 4.0),
        "circle": (Geom_Circle(frame, 5.0), 0.3, 4.0),
        "line": (Geom_Line(gp_Pnt(1, 2, 3), gp_Dir(1, 1, 0)), -2.0, 5.0),
    }


def swept(kind: str, curve, t0: float, t1: float):
    if kind == "extrusion":
        return make_face(Geom_SurfaceOfLinearExtrusion(curve, gp_Dir(0.1, 0.2, 1)), t0, t1,
                         -2.0, 7.0)
    axis = gp_Ax1(gp_Pnt(-20, 1, 0), gp_Dir(0.05, 1, 0.1))
    return make_face(Geom_SurfaceOfRevolution(curve, axis), 0.2, 5.0, t0, t1)


def built_faces() -> dict:
    faces = {
        "nurbs-converted torus": faces_of(BRepBuilderAPI_NurbsConvert(
            BRepPrimAPI_MakeTorus(20.0, 6.0, 2.0).Shape(), True).Shape())[0],
        "nurbs-converted cylinder": faces_of(BRepBuilderAPI_NurbsConvert(
            BRepPrimAPI_MakeCylinder(7.0, 12.0).Shape(), True).Shape())[0],
        "C1 bspline": make_face(c1_bspline()),
        "C1 bspline, box edge on the knot": make_face(c1_bspline(), 0.1, 0.4, 0.3, 0.9),
        "periodic bspline": make_face(periodic_bspline()),
        "periodic bspline, shifted box": make_face(periodic_bspline(), -3.0, 1.5, 0.2, 0.5),
        "bezier": make_face(bezier()),
        "bezier, sub-box": make_face(bezier(), 0.2, 0.7, 0.1, 0.5),
        "revolution near its axis": make_face(Geom_SurfaceOfRevolution(
            Geom_TrimmedCurve(Geom_Line(gp_Pnt(3e-8, 0, 0), gp_Dir(1, 0, 1)), 0.0, 5.0),
            gp_Ax1(gp_Pnt(), gp_Dir(0, 0, 1))), 0.0, 6.0, 0.0, 5.0),
        "offset bspline": make_face(Geom_OffsetSurface(c1_bspline(), 2.0)),
        "offset periodic": make_face(Geom_OffsetSurface(periodic_bspline(), -1.0), 0.5, 6.0,
                                     0.1, 0.9),
        "offset bezier": make_face(Geom_OffsetSurface(bezier(), 0.5)),
        "offset cylinder": make_face(Geom_OffsetSurface(Geom_CylindricalSurface(
            gp_Ax3(gp_Pnt(1, 2, 3), gp_Dir(0, 1, 1)), 5.0), 1.0), 0.0, 5.0, -3.0, 4.0),
        "offset torus": make_face(Geom_OffsetSurface(Geom_ToroidalSurface(
            gp_Ax3(), 10.0, 3.0), -1.0), 0.0, 5.0, -1.2, 6.2),
    }
    for name, (curve, t0, t1) in basis_curves().items():
        for kind in ("extrusion", "revolution"):
            faces[f"{kind} of {name}"] = swept(kind, curve, t0, t1)
        faces[f"offset revolution of {name}"] = make_face(Geom_OffsetSurface(
            Geom_SurfaceOfRevolution(curve, gp_Ax1(gp_Pnt(-20, 1, 0), gp_Dir(0.05, 1, 0.1))),
            -0.7), 0.2, 5.0, t0, t1)
    turn = gp_Trsf()
    turn.SetRotation(gp_Ax1(gp_Pnt(1, 2, 3), gp_Dir(1, 1, 1)), 0.7)
    turn.SetTranslationPart(gp_Vec(10, -5, 2))
    mirror = gp_Trsf()
    mirror.SetMirror(gp_Ax2(gp_Pnt(3, 0, 0), gp_Dir(1, 0.2, 0)))
    for name in ("C1 bspline", "revolution of spline", "offset bezier"):
        moved = faces[name].Moved(TopLoc_Location(turn))
        faces[f"{name}, moved"] = moved
        faces[f"{name}, moved and reversed"] = TopoDS.Face_s(moved.Reversed())
        faces[f"{name}, mirrored"] = faces[name].Moved(TopLoc_Location(mirror))
    return faces


BUILT = built_faces()


# -- tests ------------------------------------------------------------------------------------
def test_kind_codes_are_occts():
    assert (ev.PLANE, ev.CYLINDER, ev.CONE, ev.SPHERE, ev.TORUS, ev.BEZIER, ev.BSPLINE,
            ev.REVOLUTION, ev.EXTRUSION, ev.OFFSET) == tuple(int(k) for k in (
                GeomAbs.GeomAbs_Plane, GeomAbs.GeomAbs_Cylinder, GeomAbs.GeomAbs_Cone,
                GeomAbs.GeomAbs_Sphere, GeomAbs.GeomAbs_Torus, GeomAbs.GeomAbs_BezierSurface,
                GeomAbs.GeomAbs_BSplineSurface, GeomAbs.GeomAbs_SurfaceOfRevolution,
                GeomAbs.GeomAbs_SurfaceOfExtrusion, GeomAbs.GeomAbs_OffsetSurface))


# abc_fold's face 18 (cut from a real part, fixtures/README.md) is a B-spline blend whose u
# span is 0.0086: r_uu is 8.3e4 mm and the compiled evaluator differs from OCCT there by
# 1.7e-12 of it (ratio 1.7; r, r_u, r_w, r_uw, r_ww stay below 0.08). Round-off of a badly
# scaled parameter, left for the evaluators' owner to judge; strict, so a fix shows.
ROUND_OFF = {"abc_fold.step": "r_uu 1.7e-12 relative on a 0.0086-wide u span (face 18)"}


@pytest.mark.parametrize("path", [
    pytest.param(p, marks=pytest.mark.xfail(strict=True, reason=ROUND_OFF[p.name]))
    if p.name in ROUND_OFF else p for p in FIXTURES], ids=lambda p: p.name)
def test_fixture_faces_match_occt(path):
    shape = read_step(path)
    size = size_of(shape)
    for i, face in enumerate(faces_of(shape), 1):
        if FaceSurface(face).kind == "other":
            assert surface_data(face) is None
            continue
        assert worst_ratio(face, size) <= 1.0, (path.name, i)


@pytest.mark.parametrize("name", sorted(BUILT))
def test_built_faces_match_occt(name):
    face = BUILT[name]
    assert worst_ratio(face, size_of(face)) <= 1.0


def test_location_is_kept_apart_and_orientation_ignored():
    moved = surface_data(BUILT["C1 bspline, moved"])
    plain = surface_data(BUILT["C1 bspline"])
    assert moved.ints[0] == 1 and plain.ints[0] == 0
    np.testing.assert_array_equal(moved.poles, plain.poles)  # in the surface's own frame
    flipped = surface_data(BUILT["C1 bspline, moved and reversed"])
    np.testing.assert_array_equal(flipped.params, moved.params)


@pytest.mark.parametrize("curve", [
    Geom_TrimmedCurve(Geom_Parabola(gp_Ax2(), 2.0), -3.0, 3.0),
    Geom_TrimmedCurve(Geom_Hyperbola(gp_Ax2(), 5.0, 3.0), -1.0, 1.0),
], ids=["parabola", "hyperbola"])
def test_unsupported_basis_curves_give_none(curve):
    for kind in ("extrusion", "revolution"):
        face = swept(kind, curve, -1.0, 1.0)
        assert FaceSurface(face).kind == kind
        assert surface_data(face) is None
    offset = make_face(Geom_OffsetSurface(Geom_SurfaceOfLinearExtrusion(curve, gp_Dir(0, 0, 1)),
                                          1.0), -1.0, 1.0, 0.0, 2.0)
    assert FaceSurface(offset).kind == "offset" and surface_data(offset) is None


def test_offset_at_a_singular_point_asks_occt():
    """At the pole of an offset sphere the basis normal vanishes: OCCT switches to its
    osculating-surface treatment, the kernel answers SINGULAR (the caller falls back)."""
    face = make_face(Geom_OffsetSurface(Geom_SphericalSurface(gp_Ax3(), 5.0), 1.0), 0.0, 5.0,
                     -math.pi / 2, math.pi / 2)
    data = surface_data(face)
    out = np.zeros((6, 3))
    assert ev.d2(*data.args, 1.0, math.pi / 2, ev.new_work(), out) == ev.SINGULAR
    assert ev.d2(*data.args, 1.0, 1.0, ev.new_work(), out) == ev.OK


@numba.njit  # not cached: a cached caller keeps its copy of d2 when the kernel changes
def _sum_over(kind, params, ints, knots_u, knots_v, poles, weights, uw, work, out):
    """A compiled caller: sum of d2's rows over the points uw ((n, 2))."""
    total = np.zeros((6, 3))
    for k in range(uw.shape[0]):
        ev.d2(kind, params, ints, knots_u, knots_v, poles, weights, uw[k, 0], uw[k, 1], work,
              out)
        total += out
    return total


def test_d2_is_callable_from_compiled_code():
    face = BUILT["offset revolution of nurbs arc"]
    data = surface_data(face)
    uw = uv_samples(FaceSurface(face), 20)
    work, out = ev.new_work(), np.zeros((6, 3))
    expected = np.zeros((6, 3))
    for u, w in uw:
        ev.d2(*data.args, u, w, work, out)
        expected += out
    np.testing.assert_array_equal(_sum_over(*data.args, uw, work, out), expected)


@pytest.mark.parametrize("name", ["C1 bspline, moved", "revolution of spline",
                                  "extrusion of nurbs arc", "periodic bspline"])
def test_d3_matches_occt(name):
    """Third derivatives (OCCT order D3U, D3V, D3UUV, D3UVV) under the same tolerance."""
    face = BUILT[name]
    fs, data, size = FaceSurface(face), surface_data(face), size_of(face)
    work, out = ev.new_work(), np.zeros((10, 3))
    for u, w in uv_samples(fs):
        assert ev.d3(*data.args, u, w, work, out) == ev.OK
        ref = np.array(fs.third_derivatives(u, w))
        err = np.linalg.norm(out[6:] - ref, axis=1)
        assert np.all(err <= TOL * (size + np.linalg.norm(ref, axis=1))), (name, u, w)
