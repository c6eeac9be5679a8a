"""cadcnc: direct interpolation of ball-end cutter paths along the intersection of two faces.

Data flow: STEP/CadQuery shape -> :class:`Part` (faces, adjacency) -> :class:`FaceSurface`
(derivatives, normals, curvature, trims) -> interpolator (one cycle at a time,
:class:`Stepper`) -> :class:`Toolpath` -> writers, verification, plots. Units: mm, mm/min, s.
"""

from .errors import (
    CadcncError, FaceNumberError, FacePairError, GeometryError, InputError, OutputError,
    SingularPointError, StartPointError, StepFileError,
)
from .face_surface import FaceSurface
from .part import Part, SharedEdge, load_step
from .path import intersection_path, intersection_paths, make_stepper
from .stepper import Stepper, Tangency
from .tolerances import Tolerances
from .toolpath import Toolpath
from .verification import VerificationReport, verify

__version__ = "0.1.0"

__all__ = [
    "CadcncError", "FaceNumberError", "FacePairError", "GeometryError", "InputError",
    "OutputError", "SingularPointError", "StartPointError", "StepFileError", "FaceSurface",
    "Part", "SharedEdge", "load_step", "intersection_path", "intersection_paths",
    "make_stepper", "Stepper", "Tangency", "Tolerances", "Toolpath", "VerificationReport",
    "verify",
]
