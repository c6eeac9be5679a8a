"""One B-rep face as a parametric surface r(u, w): derivatives, normals, curvature, trims.

This is the fence around OpenCASCADE for everything surface-related: the interpolator
takes the plain numbers this module returns. Parameters are the surface's native (u, w)
(OCCT's (U, V)); lengths are mm, curvatures 1/mm. The normal points out of the material:
r_u x r_w normalised, flipped when the face is REVERSED in its shell.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepGProp import BRepGProp
from OCP.BRepTools import BRepTools
from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.GProp import GProp_GProps
from OCP.Precision import Precision
from OCP.ShapeAnalysis import ShapeAnalysis_Surface
from OCP.TopAbs import TopAbs_IN, TopAbs_ON, TopAbs_REVERSED
from OCP.TopoDS import TopoDS_Face

from ..core.errors import GeometryError, InputError, SingularPointError
from ..core.tolerances import CONFUSION, DEFAULT, Tolerances
from . import differential as dg
from .boxes import optimal_box
from .surface_data import SURFACE_KINDS, SurfaceData, as_topods_face, surface_data

if TYPE_CHECKING:   # built on first use (trim_grid imports the compiled reader)
    from .trim_grid import TrimGrid
from ..core.trim_labels import BOUNDARY, INSIDE, OUTSIDE


@dataclass(frozen=True)
class Derivatives:
    """r and its partial derivatives at (u, w); each a (3,) float array in mm."""

    r: np.ndarray
    ru: np.ndarray
    rw: np.ndarray
    ruu: np.ndarray
    ruw: np.ndarray
    rww: np.ndarray


class FaceSurface:
    """A trimmed B-rep face viewed as r(u, w) with its outward (cutter-side) normal.

    ``number`` is the 1-based face number in the owning part (None for a loose face).
    """

    def __init__(self, face, number: int | None = None, tol: Tolerances = DEFAULT,
                 part=None, whole: bool = False):
        self.topods = as_topods_face(face)
        self.whole = whole
        """True for a face whose boundary no one asks (a guide plane streamed with its
        steppers' boundary checks off): its kernel's trim grid reads every point inside,
        built at no cost."""
        self.number = number
        self.part = part
        self.tol = tol
        self._adaptor = BRepAdaptor_Surface(self.topods, True)
        self.kind = SURFACE_KINDS.get(self._adaptor.GetType(), "other")
        self.reversed = self.topods.Orientation() == TopAbs_REVERSED
        self._sign = -1.0 if self.reversed else 1.0
        umin, umax, wmin, wmax = BRepTools.UVBounds_s(self.topods)
        self.u_range = (umin, umax)
        self.w_range = (wmin, wmax)
        self.u_period = self._adaptor.UPeriod() if self._adaptor.IsUPeriodic() else None
        self.w_period = self._adaptor.VPeriod() if self._adaptor.IsVPeriodic() else None
        self.clear_caches()
        self._box: tuple[np.ndarray, np.ndarray] | None = None
        self.derived: dict = {}
        """What other stages build once from this face (the guard's cells and trees), by
        its owner's key: kept with the face, dropped with it."""
        # scratch objects reused by every evaluation (keeps allocation out of hot loops)
        self._p = gp_Pnt()
        self._v = [gp_Vec() for _ in range(9)]

    def box(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo (3,), hi (3,)) of OCCT's optimal box of the face's geometry, mm (computed
        once; copies)."""
        if self._box is None:
            self._box = optimal_box(self.topods, use_triangulation=False)
        return self._box[0].copy(), self._box[1].copy()

    def __repr__(self) -> str:
        name = f"Face{self.number}" if self.number else "face"
        return f"<FaceSurface {name} {self.kind}{' reversed' if self.reversed else ''}>"

    def clear_caches(self) -> None:
        """Drop the per-face data built on first use (trim classifier, SurfaceData and trim
        grid, point projectors): the next path pays them again, as a first call does."""
        self._classifier = None
        self._kernel: tuple | None = None
        self._projectors: dict = {}

    # -- parameters -------------------------------------------------------------------
    @property
    def periodic(self) -> tuple[bool, bool]:
        return self.u_period is not None, self.w_period is not None

    def wrap(self, u: float, w: float) -> tuple[float, float]:
        """Wrap periodic parameters into [min, min + period) of the face's range."""
        if self.u_period is not None:
            u = self.u_range[0] + (u - self.u_range[0]) % self.u_period
        if self.w_period is not None:
            w = self.w_range[0] + (w - self.w_range[0]) % self.w_period
        return u, w

    def classify(self, u: float, w: float) -> str:
        """Whether (u, w) lies inside the trimmed face, on its boundary, or outside."""
        if self._classifier is None:
            # the classifier's tolerance is in (u, w): convert the 3-D one (mm)
            tol = self.tol.on_boundary
            tol_uv = min(self._adaptor.UResolution(tol), self._adaptor.VResolution(tol))
            self._classifier = BRepTopAdaptor_FClass2d(self.topods, tol_uv)
        state = self._classifier.Perform(gp_Pnt2d(*self.wrap(u, w)))
        if state == TopAbs_IN:
            return INSIDE
        return BOUNDARY if state == TopAbs_ON else OUTSIDE

    def classify_grid(self, us, ws) -> np.ndarray:
        """(len(us), len(ws)) object array: :meth:`classify` of every node of the grid
        ``us`` x ``ws``, read from the kernel's trim grid where the face has one (the same
        answers, FClass2d asked only in its MIXED cells), else node by node."""
        if self.kernel:
            return self.kernel[1].classify_grid(us, ws)
        return np.array([[self.classify(u, w) for w in ws] for u in us], dtype=object)

    def contains(self, u: float, w: float) -> bool:
        """True for points inside the trimmed face or on its boundary."""
        return self.classify(u, w) != OUTSIDE

    @property
    def kernel(self) -> tuple[SurfaceData, "TrimGrid"] | None:
        """(surface data, trim grid) for the compiled stepper, built on first use (the
        grid build is planning time, reported by benchmarks/kernel/bench_trim_grid.py); None
        where the kernel cannot evaluate this face (OCCT's evaluation is used)."""
        if self._kernel is None:
            data = surface_data(self)
            # imported here: the grid's build compiles with numba (0.4 s to import), which
            # listing a part's faces (`cadcnc faces`) does not need
            from .trim_grid import TrimGrid

            grid = TrimGrid.whole(self) if self.whole else TrimGrid.build(self, data=data)
            self._kernel = (data, grid) if data is not None else ()
        return self._kernel or None

    # -- evaluation ---------------------------------------------------------------------
    def point(self, u: float, w: float) -> np.ndarray:
        """r(u, w), (3,) mm."""
        self._adaptor.D0(u, w, self._p)
        return np.array(self._p.Coord())

    def derivatives(self, u: float, w: float) -> Derivatives:
        """r, r_u, r_w, r_uu, r_uw, r_ww at (u, w) (OCCT's D2)."""
        p, v = self._p, self._v
        self._adaptor.D2(u, w, p, v[0], v[1], v[2], v[3], v[4])
        # OCCT order: D1U, D1V, D2U, D2V, D2UV
        return Derivatives(
            np.array(p.Coord()), np.array(v[0].Coord()), np.array(v[1].Coord()),
            np.array(v[2].Coord()), np.array(v[4].Coord()), np.array(v[3].Coord()),
        )

    def derivatives_array(self, u: float, w: float, out: np.ndarray) -> np.ndarray:
        """Fill ``out`` ((6, 3) float) with r, r_u, r_w, r_uu, r_uw, r_ww; the fast path."""
        p, v = self._p, self._v
        self._adaptor.D2(u, w, p, v[0], v[1], v[2], v[3], v[4])
        out[0] = p.Coord()
        out[1] = v[0].Coord()
        out[2] = v[1].Coord()
        out[3] = v[2].Coord()
        out[4] = v[4].Coord()
        out[5] = v[3].Coord()
        return out

    def derivative_tuples(self, u: float, w: float) -> tuple:
        """(r, r_u, r_w, r_uu, r_uw, r_ww) as float 3-tuples: the interpolator's hot path."""
        p, v = self._p, self._v
        self._adaptor.D2(u, w, p, v[0], v[1], v[2], v[3], v[4])
        return p.Coord(), v[0].Coord(), v[1].Coord(), v[2].Coord(), v[4].Coord(), v[3].Coord()

    def parameter_lengths(self) -> tuple[float, float]:
        """Approximate lengths (mm) of the face's u and w parameter ranges on the surface
        (the largest |r_u| (u1 - u0) and |r_w| (w1 - w0) over a 5 x 5 grid; at least 1e-6),
        used to size sampling grids and cells."""
        (u0, u1), (w0, w1) = self.u_range, self.w_range
        out = np.empty((6, 3))
        lu = lw = 0.0
        for u in np.linspace(u0, u1, 5):
            for w in np.linspace(w0, w1, 5):
                d = self.derivatives_array(u, w, out)
                lu = max(lu, float(np.linalg.norm(d[1])) * (u1 - u0))
                lw = max(lw, float(np.linalg.norm(d[2])) * (w1 - w0))
        return max(lu, 1e-6), max(lw, 1e-6)   # mm: no zero length (a collapsed edge)

    @property
    def normal_sign(self) -> float:
        """+1, or -1 on a REVERSED face: multiplies r_u x r_w into the outward normal."""
        return self._sign

    def project(self, point, within_face_box: bool = True) -> tuple[float, float, float]:
        """(u, w, distance mm) of the nearest point of the surface to ``point``.

        OCCT's exact projection (GeomAPI_ProjectPointOnSurf, initialised once per face and
        kept: its sample grid of the surface is per face), restricted to the face's
        parameter box when ``within_face_box``. Where that finds no interior extremum (a
        point beyond the face's edges), falls back to the nearest point of the trimmed
        face (BRepExtrema_DistShapeShape). Raises GeometryError when both find none.
        """
        xyz = tuple(float(c) for c in point)
        if not all(math.isfinite(c) for c in xyz):
            raise InputError(f"{self!r}: cannot project the non-finite point {xyz}")
        pnt = gp_Pnt(*xyz)
        proj = self._projectors.get(within_face_box)
        if proj is None:  # its sample grid of the surface is built once per face
            proj = self._projectors[within_face_box] = GeomAPI_ProjectPointOnSurf()
            if within_face_box:
                proj.Init(self.geom_surface, *self.u_range, *self.w_range)
            else:
                # as GeomAPI_ProjectPointOnSurf(point, surface) does: Precision::Confusion
                proj.Init(self.geom_surface, *self.geom_surface.Bounds(),
                          Precision.Confusion_s())
        proj.Perform(pnt)
        if proj.IsDone() and proj.NbPoints() > 0:
            u, w = proj.LowerDistanceParameters()
            return u, w, proj.LowerDistance()
        found = nearest_on_face(self.topods, self.geom_surface, pnt)
        if found is None:
            raise GeometryError(f"{self!r}: no projection of point {xyz} found")
        return found

    def third_derivatives(self, u: float, w: float) -> tuple[np.ndarray, ...]:
        """r_uuu, r_uuw, r_uww, r_www at (u, w), where OCCT provides D3."""
        p, v = self._p, self._v
        self._adaptor.D3(u, w, p, v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8])
        # OCCT order: ..., D3U, D3V, D3UUV, D3UVV
        return (np.array(v[5].Coord()), np.array(v[7].Coord()),
                np.array(v[8].Coord()), np.array(v[6].Coord()))

    def singularity(self, ru: np.ndarray, rw: np.ndarray) -> float:
        """|r_u x r_w| / (|r_u|^2 + |r_w|^2): 0 at a singular point, 1/2 for a square grid."""
        c = dg.cross(ru, rw)
        return float(math.sqrt(c @ c) / (ru @ ru + rw @ rw + 1e-300))   # 0 / 0 -> 0

    def normal(self, u: float, w: float) -> np.ndarray:
        """Unit normal out of the material, (3,). Raises SingularPointError where undefined
        and InputError for non-finite parameters: it never returns NaN."""
        if not (math.isfinite(u) and math.isfinite(w)):
            raise InputError(f"{self!r}: parameters must be finite, got (u={u}, w={w})")
        d = self.derivatives(u, w)
        return self._normal_from(d.ru, d.rw, u, w)

    def _normal_from(self, ru, rw, u, w) -> np.ndarray:
        if self.singularity(ru, rw) < self.tol.singular:
            raise SingularPointError(
                f"{self!r}: singular parameter point (u={u:.6g}, w={w:.6g}): "
                "r_u x r_w vanishes (pole, apex or degenerate edge), no normal", u, w)
        c = dg.cross(ru, rw)
        return self._sign * c / np.linalg.norm(c)

    def is_singular(self, u: float, w: float) -> bool:
        d = self.derivatives(u, w)
        return self.singularity(d.ru, d.rw) < self.tol.singular

    def fundamental_forms(self, u: float, w: float) -> dg.FundamentalForms:
        d = self.derivatives(u, w)
        n = self._normal_from(d.ru, d.rw, u, w)
        return dg.fundamental_forms(d.ru, d.rw, d.ruu, d.ruw, d.rww, n)

    def normal_curvature(self, u: float, w: float, direction) -> float:
        """Normal curvature (1/mm) along 3-D tangent ``direction`` (projected on the plane)."""
        d = self.derivatives(u, w)
        n = self._normal_from(d.ru, d.rw, u, w)
        ff = dg.fundamental_forms(d.ru, d.rw, d.ruu, d.ruw, d.rww, n)
        return dg.normal_curvature(ff, *dg.tangent_coordinates(ff, d.ru, d.rw, direction))

    def principal_curvatures(self, u: float, w: float) -> dg.PrincipalCurvatures:
        d = self.derivatives(u, w)
        n = self._normal_from(d.ru, d.rw, u, w)
        ff = dg.fundamental_forms(d.ru, d.rw, d.ruu, d.ruw, d.rww, n)
        return dg.principal_curvatures(ff, d.ru, d.rw)

    def geodesic_torsion(self, u: float, w: float, direction) -> float:
        t = np.asarray(direction, dtype=float)
        return dg.geodesic_torsion(self.principal_curvatures(u, w), t / np.linalg.norm(t))

    # -- OCCT handles for the verification layer ----------------------------------------
    @property
    def geom_surface(self):
        """The face's Geom_Surface handle, with the face's location applied."""
        return BRep_Tool.Surface_s(self.topods)

    def area(self) -> float:
        """Face area, mm^2."""
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(self.topods, props)
        return props.Mass()


def nearest_on_face(face: TopoDS_Face, surface, pnt: gp_Pnt):
    """(u, w, distance mm) of the nearest point of the trimmed ``face`` to ``pnt``, or
    None. The point may lie on an edge or a vertex: its (u, w) comes from
    ShapeAnalysis_Surface.ValueOfUV of that point, which lies on the surface."""
    dss = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(pnt).Vertex(), face)
    if not dss.IsDone() or dss.NbSolution() == 0:
        return None
    near = dss.PointOnShape2(1)
    uv = ShapeAnalysis_Surface(surface).ValueOfUV(near, CONFUSION)
    return uv.X(), uv.Y(), float(dss.Value())
