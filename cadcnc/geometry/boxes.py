"""OCCT's optimal bounding boxes of shapes. Lengths mm.

``BRepBndLib.AddOptimal`` costs about 30 ms a free-form face: a part's face keeps its own
box (:meth:`~cadcnc.geometry.face_surface.FaceSurface.box`), which the part's box, the
guards and the gate's probes share; nothing is kept here.
"""

from __future__ import annotations

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib


def optimal_box(shape, use_triangulation: bool) -> tuple[np.ndarray, np.ndarray]:
    """(lo (3,), hi (3,)) of OCCT's optimal axis-aligned bounding box of a shape, mm (of
    its geometry, or of its triangulation)."""
    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape, box, use_triangulation, False)
    xmin, ymin, zmin, xmax, ymax, zmax = box.Get()
    return np.array([xmin, ymin, zmin]), np.array([xmax, ymax, zmax])
