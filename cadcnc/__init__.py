"""cadcnc: direct interpolation of ball-end cutter paths along the intersection of two faces.

Data flow (docs/architecture.md): STEP/CadQuery shape -> :class:`Part` (faces, adjacency)
-> :class:`FaceSurface` (derivatives, normals, curvature, trims) -> interpolation core
(one cycle at a time, :class:`Stepper`) -> :class:`Toolpath` -> writers, verification,
plots. Units: mm, mm/min, s.
"""

from .errors import (
    CadcncError, FaceNumberError, FacePairError, GeometryError, InputError, OutputError,
    SingularPointError, StartPointError, StepFileError,
)
from .geometry.face_surface import FaceSurface
from .geometry.part import Part, SharedEdge, load_step
from .interp.stepper import Stepper, Tangency
from .ops.pair_path import intersection_path, intersection_paths, make_stepper
from .program.toolpath import Toolpath
from .tolerances import Tolerances
from .verification import VerificationReport, verify

__version__ = "0.1.0"

__all__ = [
    "CadcncError", "FaceNumberError", "FacePairError", "GeometryError", "InputError",
    "OutputError", "SingularPointError", "StartPointError", "StepFileError", "FaceSurface",
    "Part", "SharedEdge", "load_step", "intersection_path", "intersection_paths",
    "make_stepper", "Stepper", "Tangency", "Tolerances", "Toolpath", "VerificationReport",
    "verify",
]
