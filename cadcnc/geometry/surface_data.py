"""A face's surface as flat numeric arrays for the compiled evaluators (interp/kernel).

``surface_data(face)`` reads the face's Geom_Surface the way ``BRepAdaptor_Surface`` (and
so ``FaceSurface``) evaluates it: the surface in its own frame (BRep_Tool::Surface with the
location split off), rectangular trims unwrapped to their basis, the face's
TopLoc_Location kept as a separate affine map applied to the evaluated point and
derivatives (not baked into the geometry: with a scaling location OCCT's transformed
surface would change parameterisation), and the face's parameter box (UVBounds), which
OCCT's B-spline evaluation consults at the box edges. The layout of the arrays is
documented in ``cadcnc/interp/kernel/evaluators.py``; kind codes are OCCT's
GeomAbs_SurfaceType / GeomAbs_CurveType values. Lengths mm, angles rad.

Anything not supported (other surface or basis-curve types, nested offsets, degrees over
25) gives None: the caller keeps OCCT's evaluation for that face.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepTools import BRepTools
from OCP.BSplCLib import BSplCLib
from OCP.Geom import (
    Geom_BezierCurve,
    Geom_BezierSurface,
    Geom_BSplineCurve,
    Geom_BSplineSurface,
    Geom_Circle,
    Geom_ConicalSurface,
    Geom_CylindricalSurface,
    Geom_Ellipse,
    Geom_Line,
    Geom_OffsetSurface,
    Geom_Plane,
    Geom_RectangularTrimmedSurface,
    Geom_SphericalSurface,
    Geom_SurfaceOfLinearExtrusion,
    Geom_SurfaceOfRevolution,
    Geom_ToroidalSurface,
    Geom_TrimmedCurve,
)
from OCP.GeomAbs import (
    GeomAbs_BezierCurve,
    GeomAbs_BezierSurface,
    GeomAbs_BSplineCurve,
    GeomAbs_BSplineSurface,
    GeomAbs_Circle,
    GeomAbs_Cone,
    GeomAbs_Cylinder,
    GeomAbs_Ellipse,
    GeomAbs_Line,
    GeomAbs_OffsetSurface,
    GeomAbs_Plane,
    GeomAbs_Sphere,
    GeomAbs_SurfaceOfExtrusion,
    GeomAbs_SurfaceOfRevolution,
    GeomAbs_Torus,
)
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Face

from ..core.errors import InputError
from . import bspline_blob

SURFACE_KINDS = {
    GeomAbs_Plane: "plane",
    GeomAbs_Cylinder: "cylinder",
    GeomAbs_Cone: "cone",
    GeomAbs_Sphere: "sphere",
    GeomAbs_Torus: "torus",
    GeomAbs_BezierSurface: "bezier",
    GeomAbs_BSplineSurface: "bspline",
    GeomAbs_SurfaceOfRevolution: "revolution",
    GeomAbs_SurfaceOfExtrusion: "extrusion",
    GeomAbs_OffsetSurface: "offset",
}
"""OCCT surface types and the names FaceSurface.kind gives them."""


def as_topods_face(face) -> TopoDS_Face:
    """Accept a CadQuery ``Face``, a ``TopoDS_Face`` or a ``FaceSurface``."""
    if isinstance(getattr(face, "topods", None), TopoDS_Face):   # a FaceSurface
        return face.topods
    wrapped = getattr(face, "wrapped", face)
    if isinstance(wrapped, TopoDS_Face):
        return wrapped
    try:
        return TopoDS.Face_s(wrapped)
    except Exception as exc:  # OCP raises Standard_TypeMismatch for non-faces
        raise InputError(f"expected a face, got {type(face).__name__}") from exc


MAX_DEGREE = BSplCLib.MaxDegree_s()  # 25: no B-spline is higher; the kernel is sized for it
_KIND_CODES = {
    Geom_Plane: int(GeomAbs_Plane),
    Geom_CylindricalSurface: int(GeomAbs_Cylinder),
    Geom_ConicalSurface: int(GeomAbs_Cone),
    Geom_SphericalSurface: int(GeomAbs_Sphere),
    Geom_ToroidalSurface: int(GeomAbs_Torus),
    Geom_BezierSurface: int(GeomAbs_BezierSurface),
    Geom_BSplineSurface: int(GeomAbs_BSplineSurface),
    Geom_SurfaceOfRevolution: int(GeomAbs_SurfaceOfRevolution),
    Geom_SurfaceOfLinearExtrusion: int(GeomAbs_SurfaceOfExtrusion),
    Geom_OffsetSurface: int(GeomAbs_OffsetSurface),
}
_NAMES = {int(code): name for code, name in SURFACE_KINDS.items()}
_NO_KNOTS = np.zeros(0)
_NO_POLES = np.zeros((0, 0, 3))
_NO_WEIGHTS = np.zeros((0, 0))


@dataclass(frozen=True)
class SurfaceData:
    """One face's surface as the evaluators' arguments (see interp/kernel/evaluators.py).

    kind: GeomAbs_SurfaceType value; params (m,) float64 and ints (k,) int64: location,
    parameter box and the kind's numbers; knots_u, knots_v flat knots; poles
    (n_u, n_v, 3) mm; weights (n_u, n_v) (ones when not rational).
    """

    kind: int
    params: np.ndarray
    ints: np.ndarray
    knots_u: np.ndarray
    knots_v: np.ndarray
    poles: np.ndarray
    weights: np.ndarray

    @property
    def kind_name(self) -> str:
        """FaceSurface.kind's name for this kind ('plane', 'bspline', ...)."""
        return _NAMES[self.kind]

    @property
    def args(self) -> tuple:
        """(kind, params, ints, knots_u, knots_v, poles, weights): d2's leading arguments."""
        return (self.kind, self.params, self.ints, self.knots_u, self.knots_v, self.poles,
                self.weights)


def surface_data(face) -> SurfaceData | None:
    """The face's surface as a SurfaceData, or None when the kernel cannot evaluate it.

    ``face``: a FaceSurface, a CadQuery Face or a TopoDS_Face.
    """
    topods = as_topods_face(face)
    loc = TopLoc_Location()
    surf = BRep_Tool.Surface_s(topods, loc)
    if surf is None:
        return None
    body = _surface(_unwrap_surface(surf))
    if body is None:
        return None
    kind, fparams, iparams, arrays = body
    trsf = loc.Transformation()
    matrix = [trsf.Value(i, j) for i in (1, 2, 3) for j in (1, 2, 3)]
    shift = [trsf.Value(i, 4) for i in (1, 2, 3)]
    box = list(BRepTools.UVBounds_s(topods))
    params = np.array(matrix + shift + box + fparams, dtype=np.float64)
    ints = np.array([0 if loc.IsIdentity() else 1] + iparams, dtype=np.int64)
    knots_u, knots_v, poles, weights = arrays
    return SurfaceData(kind, params, ints, knots_u, knots_v, poles, weights)


def _unwrap_surface(surf):
    while isinstance(surf, Geom_RectangularTrimmedSurface):
        surf = surf.BasisSurface()
    return surf


def _xyz(obj) -> list[float]:
    return list(obj.XYZ().Coord())


def _frame(ax3) -> list[float]:
    """Origin, XDirection, YDirection, Direction of a gp_Ax3 / gp_Ax2 (12 floats)."""
    return (_xyz(ax3.Location()) + _xyz(ax3.XDirection()) + _xyz(ax3.YDirection())
            + _xyz(ax3.Direction()))


def _surface(surf):
    """(kind, float body, int body, (knots_u, knots_v, poles, weights)) or None."""
    kind = _KIND_CODES.get(type(surf))
    if kind is None:
        return None
    empty = (_NO_KNOTS, _NO_KNOTS, _NO_POLES, _NO_WEIGHTS)
    if isinstance(surf, Geom_Plane):
        return kind, _frame(surf.Position()), [], empty
    if isinstance(surf, (Geom_CylindricalSurface, Geom_SphericalSurface)):
        return kind, _frame(surf.Position()) + [surf.Radius()], [], empty
    if isinstance(surf, Geom_ConicalSurface):
        return kind, _frame(surf.Position()) + [surf.RefRadius(), surf.SemiAngle()], [], empty
    if isinstance(surf, Geom_ToroidalSurface):
        radii = [surf.MajorRadius(), surf.MinorRadius()]
        return kind, _frame(surf.Position()) + radii, [], empty
    if isinstance(surf, (Geom_BSplineSurface, Geom_BezierSurface)):
        return _poles_surface(kind, surf)
    if isinstance(surf, (Geom_SurfaceOfLinearExtrusion, Geom_SurfaceOfRevolution)):
        curve = _curve(surf.BasisCurve())
        if curve is None:
            return None
        cfloats, cints, arrays = curve
        if isinstance(surf, Geom_SurfaceOfLinearExtrusion):
            axis = _xyz(surf.Direction())
        else:
            axis = _xyz(surf.Location()) + _xyz(surf.Direction())
        return kind, axis + cfloats, cints, arrays
    # offset: one level over a supported, non-offset basis
    basis = _unwrap_surface(surf.BasisSurface())
    inner = None if isinstance(basis, Geom_OffsetSurface) else _surface(basis)
    if inner is None:
        return None
    bkind, bfloats, bints, arrays = inner
    return kind, [surf.Offset()] + bfloats, [bkind] + bints, arrays


def _centred(poles: np.ndarray) -> tuple[list[float], np.ndarray]:
    """(origin, poles - origin), origin the middle of the poles' box: the kernel sums
    small numbers (derivatives lose fewer digits on a part far from the origin)."""
    flat = poles.reshape(-1, 3)
    origin = 0.5 * (flat.min(axis=0) + flat.max(axis=0))
    return origin.tolist(), poles - origin


def _flat(seq) -> np.ndarray:
    return np.array([seq.Value(i) for i in range(seq.Lower(), seq.Upper() + 1)])


def _bezier_knots(degree: int) -> np.ndarray:
    return np.array([0.0] * (degree + 1) + [1.0] * (degree + 1))


def _poles_surface(kind: int, surf):
    p, q = surf.UDegree(), surf.VDegree()
    if max(p, q) > MAX_DEGREE:
        return None
    nu, nv = surf.NbUPoles(), surf.NbVPoles()
    rational = surf.IsURational() or surf.IsVRational()
    # a B-spline's numbers in one OCCT call (geometry/bspline_blob.py); else pole by pole
    read = bspline_blob.surface(surf) if isinstance(surf, Geom_BSplineSurface) else None
    if read is not None:
        poles, blob_weights, (uk, um), (vk, vm) = read
        weights = blob_weights if rational else np.ones((nu, nv))
    else:
        poles = np.array([[surf.Pole(i, j).Coord() for j in range(1, nv + 1)]
                          for i in range(1, nu + 1)], dtype=np.float64).reshape(nu, nv, 3)
        weights = np.ones((nu, nv))
        if rational:
            weights = np.array([[surf.Weight(i, j) for j in range(1, nv + 1)]
                                for i in range(1, nu + 1)], dtype=np.float64)
    if isinstance(surf, Geom_BSplineSurface):
        periodic = [int(surf.IsUPeriodic()), int(surf.IsVPeriodic())]
        # a periodic direction's flat knots extend the knots periodically: OCCT's own
        knots_u = (_flat(surf.UKnotSequence()) if read is None or periodic[0]
                   else np.repeat(uk, um))
        knots_v = (_flat(surf.VKnotSequence()) if read is None or periodic[1]
                   else np.repeat(vk, vm))
    else:
        knots_u, knots_v = _bezier_knots(p), _bezier_knots(q)
        periodic = [0, 0]
    # the knot range the cache normalises periodic parameters into (BSplCLib_CacheParams)
    ranges = [knots_u[p], knots_u[-1 - p], knots_v[q], knots_v[-1 - q]]
    origin, poles = _centred(poles)
    return kind, ranges + origin, [p, q] + periodic + [int(rational)], (knots_u, knots_v,
                                                                      poles, weights)


def _curve(curve):
    """(float body, int body, (knots, no knots, poles (n, 1, 3), weights (n, 1))) or None."""
    first, last = curve.FirstParameter(), curve.LastParameter()
    while isinstance(curve, Geom_TrimmedCurve):  # GeomAdaptor_Curve keeps the trim bounds
        curve = curve.BasisCurve()
    empty = (_NO_KNOTS, _NO_KNOTS, _NO_POLES, _NO_WEIGHTS)
    if isinstance(curve, Geom_Line):
        ax1 = curve.Position()
        return _xyz(ax1.Location()) + _xyz(ax1.Direction()), [int(GeomAbs_Line), 0, 0, 0], empty
    if isinstance(curve, Geom_Circle):
        frame = _frame(curve.Position())[:9]
        return frame + [curve.Radius()], [int(GeomAbs_Circle), 0, 0, 0], empty
    if isinstance(curve, Geom_Ellipse):
        frame = _frame(curve.Position())[:9]
        radii = [curve.MajorRadius(), curve.MinorRadius()]
        return frame + radii, [int(GeomAbs_Ellipse), 0, 0, 0], empty
    if not isinstance(curve, (Geom_BSplineCurve, Geom_BezierCurve)):
        return None
    p, n = curve.Degree(), curve.NbPoles()
    if p > MAX_DEGREE:
        return None
    poles = np.array([curve.Pole(i).Coord() for i in range(1, n + 1)]).reshape(n, 1, 3)
    rational = curve.IsRational()
    weights = np.ones((n, 1))
    if rational:
        weights = np.array([[curve.Weight(i)] for i in range(1, n + 1)], dtype=np.float64)
    if isinstance(curve, Geom_BSplineCurve):
        knots, periodic = _flat(curve.KnotSequence()), curve.IsPeriodic()
        code = GeomAbs_BSplineCurve
    else:
        knots, periodic, code = _bezier_knots(p), False, GeomAbs_BezierCurve
    origin, poles = _centred(poles)
    floats = [first, last, knots[p], knots[-1 - p]] + origin
    return floats, [int(code), p, int(periodic), int(rational)], (knots, _NO_KNOTS, poles,
                                                                  weights)
