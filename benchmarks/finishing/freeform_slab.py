"""A held-out-like free-form slab for the finishing benchmark
(benchmarks/finishing/finish_vs_ocl.py).

An 80 x 60 mm block whose top is one smooth bicubic B-spline face z = z(x, y) over
[0, 80] x [0, 60], with vertical sides and a flat bottom at z = 0. The poles sit on a
regular 2.5 mm grid at the Greville abscissae of uniform clamped knots, so the surface's
parameters are exactly its x and y (u = x, w = y): the top is a graph of a function and
its 3-D offset is well defined for a ball of radius up to its smallest concave radius of
curvature (about 6 mm here, measured by ``min_concave_radius``). Heights come from a
few sines (amplitude about 5 mm, slopes up to about 45 deg), not from any fixture.
Units: mm.
"""

from __future__ import annotations

import math

import numpy as np
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakePrism
from OCP.Geom import Geom_BSplineSurface
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.gp import gp_Pnt, gp_Vec
from OCP.TColgp import TColgp_Array2OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

LENGTH, WIDTH = 80.0, 60.0   # mm, along x and y
SPACING = 2.5                # mm between pole columns (and rows)
DEGREE = 3


def height(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The heights the poles take (mm); the surface smooths them (it does not interpolate)."""
    return (12.0 + 4.0 * np.sin(2 * math.pi * x / 55.0 + 0.4) * np.cos(2 * math.pi * y / 47.0 - 0.3)
            + 1.6 * np.sin(2 * math.pi * (x + 0.6 * y) / 31.0) + 0.03 * (x - 40.0))


def _knots(length: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(distinct knots, multiplicities, Greville abscissae) of a clamped uniform cubic
    B-spline over [0, length] with spans of SPACING."""
    spans = int(round(length / SPACING))
    knots = np.linspace(0.0, length, spans + 1)
    mults = np.ones(spans + 1, dtype=int)
    mults[0] = mults[-1] = DEGREE + 1
    flat = np.repeat(knots, mults)
    n_poles = spans + DEGREE
    greville = np.array([flat[i + 1:i + 1 + DEGREE].mean() for i in range(n_poles)])
    return knots, mults, greville


def _array1(values, kind):
    arr = kind(1, len(values))
    for k, v in enumerate(values, start=1):
        arr.SetValue(k, int(v) if kind is TColStd_Array1OfInteger else float(v))
    return arr


def slab_surface() -> Geom_BSplineSurface:
    """The top surface: bicubic, u = x in [0, LENGTH], w = y in [0, WIDTH]."""
    ku, mu, gu = _knots(LENGTH)
    kw, mw, gw = _knots(WIDTH)
    gx, gy = np.meshgrid(gu, gw, indexing="ij")
    z = height(gx, gy)
    poles = TColgp_Array2OfPnt(1, len(gu), 1, len(gw))
    for i in range(len(gu)):
        for j in range(len(gw)):
            poles.SetValue(i + 1, j + 1, gp_Pnt(float(gu[i]), float(gw[j]), float(z[i, j])))
    return Geom_BSplineSurface(poles, _array1(ku, TColStd_Array1OfReal),
                               _array1(kw, TColStd_Array1OfReal),
                               _array1(mu, TColStd_Array1OfInteger),
                               _array1(mw, TColStd_Array1OfInteger), DEGREE, DEGREE)


def slab_shape():
    """(TopoDS_Solid-like shape, TopoDS_Face of the B-spline top) of the slab."""
    top = BRepBuilderAPI_MakeFace(slab_surface(), 1e-7).Face()
    prism = BRepPrimAPI_MakePrism(top, gp_Vec(0.0, 0.0, -40.0)).Shape()
    box = BRepPrimAPI_MakeBox(gp_Pnt(-1.0, -1.0, 0.0), LENGTH + 2.0, WIDTH + 2.0, 100.0).Shape()
    common = BRepAlgoAPI_Common(prism, box)
    common.Build()
    if not common.IsDone():
        raise RuntimeError("the slab's boolean common failed")
    return common.Shape()


def top_face_number(part) -> int:
    """The number (1-based) of the slab's B-spline top face in a cadcnc ``Part``."""
    found = [n for n in range(1, len(part) + 1)
             if part.face(n).kind == "bspline"]
    if len(found) != 1:
        raise RuntimeError(f"expected one B-spline face on the slab, found {found}")
    return found[0]


def min_concave_radius(surface=None, step: float = 0.5) -> float:
    """Smallest radius of curvature (mm) of the top over the concave directions, sampled
    every ``step`` mm: a ball of radius below it fits every hollow."""
    surface = slab_surface() if surface is None else surface
    props = GeomLProp_SLProps(surface, 2, 1e-9)
    worst = 0.0
    for u in np.arange(0.0, LENGTH + 1e-9, step):
        for w in np.arange(0.0, WIDTH + 1e-9, step):
            props.SetParameters(float(u), float(w))
            if props.IsCurvatureDefined():
                # the normal D1U x D1V points up (+z); positive curvature = concave from above
                worst = max(worst, props.MaxCurvature(), props.MinCurvature())
    return math.inf if worst <= 0 else 1.0 / worst
