"""Face surface adapter against closed forms (analytic faces) and finite differences."""

from __future__ import annotations

import math

import cadquery as cq
import numpy as np
import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.Geom import (
    Geom_BezierSurface,
    Geom_BSplineCurve,
    Geom_OffsetSurface,
    Geom_SurfaceOfLinearExtrusion,
    Geom_SurfaceOfRevolution,
)
from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt
from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array2OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

from cadcnc.core.errors import SingularPointError
from cadcnc.core.trim_labels import BOUNDARY, INSIDE, OUTSIDE
from cadcnc.geometry.face_surface import FaceSurface

V = cq.Vector


def lateral(solid, kind):
    faces = [FaceSurface(f) for f in solid.Faces()]
    return next(f for f in faces if f.kind == kind)


def mid(fs: FaceSurface, a=0.37, b=0.61):
    return (fs.u_range[0] + a * (fs.u_range[1] - fs.u_range[0]),
            fs.w_range[0] + b * (fs.w_range[1] - fs.w_range[0]))


# -- closed forms --------------------------------------------------------------------------
def test_cylinder_boss_and_hole_normals_and_curvatures():
    a = 7.0
    boss = lateral(cq.Solid.makeCylinder(a, 20, V(0, 0, 0), V(0, 0, 1)), "cylinder")
    hole = lateral(cq.Solid.makeBox(40, 40, 10, V(-20, -20, 0)).cut(
        cq.Solid.makeCylinder(a, 10, V(0, 0, 0), V(0, 0, 1))), "cylinder")
    assert not boss.reversed and hole.reversed
    for fs, sign in ((boss, 1.0), (hole, -1.0)):
        u, w = mid(fs)
        p = fs.point(u, w)
        radial = np.array([p[0], p[1], 0.0]) / a
        np.testing.assert_allclose(fs.normal(u, w), sign * radial, atol=1e-12)
        pc = fs.principal_curvatures(u, w)
        # convex boss: k = -1/a around, 0 along; concave hole: +1/a around
        expected = (0.0, -1 / a) if sign > 0 else (1 / a, 0.0)
        assert pc.k_max == pytest.approx(expected[0], abs=1e-9)
        assert pc.k_min == pytest.approx(expected[1], abs=1e-9)
        around = np.cross([0, 0, 1.0], radial)
        assert fs.normal_curvature(u, w, around) == pytest.approx(-sign / a, abs=1e-9)
        assert fs.normal_curvature(u, w, [0, 0, 1.0]) == pytest.approx(0.0, abs=1e-9)
        # 45 deg between principal directions: tau = (k1 - k2) / 2 in magnitude
        assert abs(fs.geodesic_torsion(u, w, around + [0, 0, 1.0])) == pytest.approx(
            0.5 / a, abs=1e-9)


def test_sphere_curvature_and_pole_singularity():
    R = 12.0
    fs = lateral(cq.Solid.makeSphere(R, V(1, 2, 3), angleDegrees1=-90, angleDegrees2=90),
                 "sphere")
    u, w = mid(fs)
    np.testing.assert_allclose(fs.normal(u, w), (fs.point(u, w) - [1, 2, 3]) / R, atol=1e-12)
    pc = fs.principal_curvatures(u, w)
    assert pc.k_max == pytest.approx(-1 / R, abs=1e-9)
    assert pc.k_min == pytest.approx(-1 / R, abs=1e-9)
    assert fs.is_singular(u, fs.w_range[1]) and fs.is_singular(u, fs.w_range[0])
    with pytest.raises(SingularPointError, match="singular"):
        fs.normal(u, fs.w_range[1])


def test_torus_curvatures_outer_and_inner_equator():
    Rt, r = 20.0, 5.0
    fs = lateral(cq.Solid.makeTorus(Rt, r, V(0, 0, 0), V(0, 0, 1)), "torus")
    for v, k_around in ((0.0, -1 / (Rt + r)), (math.pi, 1 / (Rt - r))):
        u = 0.3
        p = fs.point(u, v)
        assert math.hypot(p[0], p[1]) == pytest.approx(Rt + r * math.cos(v), abs=1e-9)
        pc = fs.principal_curvatures(u, v)
        assert sorted([pc.k_max, pc.k_min]) == pytest.approx(sorted([-1 / r, k_around]),
                                                             abs=1e-9)


def test_cone_curvature():
    r1, r2, h = 20.0, 8.0, 40.0
    fs = lateral(cq.Solid.makeCone(r1, r2, h, V(0, 0, 0), V(0, 0, 1)), "cone")
    alpha = math.atan2(r1 - r2, h)  # semi-angle
    u, w = mid(fs)
    p = fs.point(u, w)
    rho = math.hypot(p[0], p[1])
    pc = fs.principal_curvatures(u, w)
    assert pc.k_min == pytest.approx(-math.cos(alpha) / rho, abs=1e-9)
    assert pc.k_max == pytest.approx(0.0, abs=1e-9)
    n = fs.normal(u, w)
    assert n[2] == pytest.approx(math.sin(alpha), abs=1e-9)  # leans up, out of the material


def test_plane_normal_flips_on_reversed_face():
    box = cq.Solid.makeBox(10, 10, 10)
    for f in box.Faces():
        fs = FaceSurface(f)
        u, w = mid(fs)
        centre_to_face = fs.point(u, w) - [5, 5, 5]
        assert fs.normal(u, w) @ centre_to_face > 4.99  # outward
        assert fs.principal_curvatures(u, w).k_max == pytest.approx(0.0, abs=1e-12)


# -- every surface kind: derivatives against finite differences of OCCT points --------------
def _face(surface, u0, u1, v0, v1):
    return FaceSurface(BRepBuilderAPI_MakeFace(surface, u0, u1, v0, v1, 1e-7).Face())


def _bspline_curve():
    pts = [(10, 0, 0), (14, 0, 5), (9, 0, 10), (13, 0, 16)]
    arr = TColgp_Array1OfPnt(1, len(pts))
    for i, p in enumerate(pts):
        arr.SetValue(i + 1, gp_Pnt(*p))
    knots, mults = TColStd_Array1OfReal(1, 2), TColStd_Array1OfInteger(1, 2)
    knots.SetValue(1, 0.0), knots.SetValue(2, 1.0)
    mults.SetValue(1, 4), mults.SetValue(2, 4)
    return Geom_BSplineCurve(arr, knots, mults, 3)


def _bezier_surface():
    poles = TColgp_Array2OfPnt(1, 4, 1, 4)
    for i in range(4):
        for j in range(4):
            poles.SetValue(i + 1, j + 1, gp_Pnt(10 * i, 10 * j, 4 * math.sin(i + 2 * j)))
    return Geom_BezierSurface(poles)


def _bspline_face():
    top = cq.Workplane().box(1, 1, 1)  # placeholder to get cq loaded
    pts = TColgp_Array2OfPnt(1, 6, 1, 6)
    for i in range(6):
        for j in range(6):
            pts.SetValue(i + 1, j + 1, gp_Pnt(8 * i, 8 * j, 3 * math.cos(i / 2) * math.sin(j / 3)))
    from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface

    api = GeomAPI_PointsToBSplineSurface()
    api.Interpolate(pts)
    del top
    return api.Surface()


def surface_kinds():
    bez = _bezier_surface()
    bsp = _bspline_face()
    yield "bezier", _face(bez, 0, 1, 0, 1)
    yield "bspline", _face(bsp, *_bounds(bsp))
    yield "revolution", _face(Geom_SurfaceOfRevolution(
        _bspline_curve(), gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1))), 0, 2 * math.pi, 0, 1)
    yield "extrusion", _face(Geom_SurfaceOfLinearExtrusion(
        _bspline_curve(), gp_Dir(0.2, 1, 0.1)), 0, 1, -5, 5)
    yield "offset", _face(Geom_OffsetSurface(bez, 2.5), 0, 1, 0, 1)
    for kind, solid in (("cylinder", cq.Solid.makeCylinder(5, 9)),
                        ("cone", cq.Solid.makeCone(6, 2, 9)),
                        ("sphere", cq.Solid.makeSphere(7)),
                        ("torus", cq.Solid.makeTorus(9, 3)),
                        ("plane", cq.Solid.makeBox(3, 4, 5))):
        yield kind, lateral(solid, kind)


def _bounds(surf):
    return surf.Bounds()


KINDS = list(surface_kinds())


@pytest.mark.parametrize("kind,fs", KINDS, ids=[k for k, _ in KINDS])
def test_every_kind_derivatives_match_finite_differences(kind, fs):
    assert fs.kind == kind
    u, w = mid(fs)
    d = fs.derivatives(u, w)
    scale_u = fs.u_range[1] - fs.u_range[0]
    scale_w = fs.w_range[1] - fs.w_range[0]
    h, k = 1e-4 * scale_u, 1e-4 * scale_w
    P = fs.point

    def fd(fun, du, dw):
        return (fun(u + du, w + dw) - fun(u - du, w - dw)) / 2

    size = np.linalg.norm(d.ru) * scale_u + np.linalg.norm(d.rw) * scale_w
    np.testing.assert_allclose(d.r, P(u, w), atol=1e-12)
    np.testing.assert_allclose(fd(P, h, 0) / h, d.ru, atol=1e-6 * size / scale_u)
    np.testing.assert_allclose(fd(P, 0, k) / k, d.rw, atol=1e-6 * size / scale_w)

    def ru(a, b):
        return fs.derivatives(a, b).ru

    def rw(a, b):
        return fs.derivatives(a, b).rw

    tol2 = 1e-5 * size
    np.testing.assert_allclose(fd(ru, h, 0) / h, d.ruu, atol=tol2 / scale_u ** 2)
    np.testing.assert_allclose(fd(ru, 0, k) / k, d.ruw, atol=tol2 / (scale_u * scale_w))
    np.testing.assert_allclose(fd(rw, 0, k) / k, d.rww, atol=tol2 / scale_w ** 2)
    # third derivatives (OCCT D3) against differences of the second
    ruuu, ruuw, ruww, rwww = fs.third_derivatives(u, w)
    np.testing.assert_allclose(fd(lambda a, b: fs.derivatives(a, b).ruu, h, 0) / h, ruuu,
                               atol=tol2 / scale_u ** 3)
    np.testing.assert_allclose(fd(lambda a, b: fs.derivatives(a, b).rww, 0, k) / k, rwww,
                               atol=tol2 / scale_w ** 3)
    # normal: unit, orthogonal to both tangents
    n = fs.normal(u, w)
    assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-12)
    assert abs(n @ d.ru) < 1e-9 * np.linalg.norm(d.ru)
    assert abs(n @ d.rw) < 1e-9 * np.linalg.norm(d.rw)


@pytest.mark.parametrize("kind,fs", KINDS, ids=[k for k, _ in KINDS])
def test_every_kind_curvature_consistent(kind, fs):
    """Normal curvature along the principal directions equals the principal curvatures,
    and the geodesic torsion vanishes there; Euler's formula holds in between."""
    u, w = mid(fs)
    pc = fs.principal_curvatures(u, w)
    assert pc.k_max >= pc.k_min
    for k, d in ((pc.k_max, pc.d_max), (pc.k_min, pc.d_min)):
        assert fs.normal_curvature(u, w, d) == pytest.approx(k, abs=1e-9)
        assert fs.geodesic_torsion(u, w, d) == pytest.approx(0.0, abs=1e-9)
    phi = 0.4
    t = math.cos(phi) * pc.d_max + math.sin(phi) * pc.d_min
    euler = pc.k_max * math.cos(phi) ** 2 + pc.k_min * math.sin(phi) ** 2
    assert fs.normal_curvature(u, w, t) == pytest.approx(euler, abs=1e-9)


def test_offset_surface_curvature_from_basis():
    """An offset by d of a sphere of radius R is a sphere of radius R + d."""
    from OCP.Geom import Geom_SphericalSurface
    from OCP.gp import gp_Ax3

    base = Geom_SphericalSurface(gp_Ax3(), 10.0)
    fs = _face(Geom_OffsetSurface(base, 2.0), 0.1, 6.0, -1.2, 1.2)
    assert fs.kind == "offset"
    u, w = 1.0, 0.3
    assert np.linalg.norm(fs.point(u, w)) == pytest.approx(12.0, abs=1e-9)
    pc = fs.principal_curvatures(u, w)
    assert pc.k_max == pytest.approx(-1 / 12.0, abs=1e-9)


# -- parameters and trims ------------------------------------------------------------------
def test_periodic_wrap_and_classification():
    fs = lateral(cq.Solid.makeCylinder(5, 10), "cylinder")
    assert fs.periodic == (True, False)
    assert fs.u_period == pytest.approx(2 * math.pi)
    u, w = fs.wrap(-0.5, 3.0)
    assert u == pytest.approx(2 * math.pi - 0.5) and w == 3.0
    np.testing.assert_allclose(fs.point(-0.5, 3.0), fs.point(u, w), atol=1e-12)
    assert fs.classify(1.0, 5.0) == INSIDE
    assert fs.classify(1.0 + 4 * math.pi, 5.0) == INSIDE  # wrapped
    assert fs.classify(1.0, 10.0) == BOUNDARY
    assert fs.classify(1.0, 10.5) == OUTSIDE


def test_trimmed_face_classification_follows_the_trim_not_the_box():
    # a plate with a round hole: the hole's centre is inside the UV box but outside the face
    plate = cq.Workplane().box(40, 40, 5).faces(">Z").workplane().hole(10)
    top = next(FaceSurface(f) for f in plate.faces(">Z").vals())
    u, w, dist = top.project((0, 0, 2.5))
    assert dist == pytest.approx(0.0, abs=1e-12)
    assert top.classify(u, w) == OUTSIDE
    u2, w2, _ = top.project((15, 15, 2.5))
    assert top.classify(u2, w2) == INSIDE
    u3, w3, _ = top.project((5, 0, 2.5))
    assert top.classify(u3, w3) == BOUNDARY


def test_cone_apex_is_singular():
    fs = lateral(cq.Solid.makeCone(6, 0, 9), "cone")
    # the apex is where the cone's lateral collapses: find it by its radius
    ws = np.linspace(*fs.w_range, 201)
    radii = [math.hypot(*fs.point(0.2, w)[:2]) for w in ws]
    w_apex = ws[int(np.argmin(radii))]
    assert min(radii) < 1e-9
    assert fs.is_singular(0.2, w_apex)
    with pytest.raises(SingularPointError):
        fs.normal(0.2, w_apex)


def test_rejects_non_faces():
    from cadcnc import InputError

    with pytest.raises(InputError, match="expected a face"):
        FaceSurface(cq.Solid.makeBox(1, 1, 1).Edges()[0])
