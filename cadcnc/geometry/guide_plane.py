"""A plane as an interpolator surface: the guide surface that carries the ball centre in
guide-surface machining (finishing passes)."""

from __future__ import annotations

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.gp import gp_Ax3, gp_Dir, gp_Pln, gp_Pnt

from ..core.tolerances import DEFAULT, Tolerances
from .face_surface import FaceSurface


def plane_surface(origin: np.ndarray, normal: np.ndarray, direction: np.ndarray,
                  size: float, tol: Tolerances = DEFAULT, whole: bool = False) -> FaceSurface:
    """The plane through ``origin`` (3,) with unit ``normal`` (3,) as a square face of half
    size ``size`` (mm) centred there; u runs along ``direction`` (3,), w across it.
    ``whole``: its boundary is never asked (:attr:`FaceSurface.whole`)."""
    ax = gp_Ax3(gp_Pnt(*map(float, origin)), gp_Dir(*map(float, normal)),
                gp_Dir(*map(float, direction)))
    face = BRepBuilderAPI_MakeFace(gp_Pln(ax), -size, size, -size, size).Face()
    return FaceSurface(face, tol=tol, whole=whole)
