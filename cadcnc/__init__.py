"""cadcnc: direct interpolation of ball-end cutter paths along the intersection of two faces.

Data flow (docs/architecture.md): STEP/CadQuery shape -> :class:`Part` (faces, adjacency)
-> :class:`FaceSurface` (derivatives, normals, curvature, trims) -> interpolation core
(one cycle at a time, :class:`Stepper`) -> :class:`Toolpath` -> writers, verification,
plots. Units: mm, mm/min, s.

The names below are loaded on first use: importing OCCT takes about 1.5 s, which
``import cadcnc`` (and ``cadcnc --help``) should not pay before it is needed.
"""

from __future__ import annotations

import importlib

from .core.errors import (
    CadcncError, FaceNumberError, FacePairError, GeometryError, InputError, OutputError,
    SingularPointError, StartPointError, StepFileError,
)
from .core.job import Finish, Job, PairPath, Pencil, Tool
from .core.tolerances import Tolerances

__version__ = "0.1.0"

_LAZY = {
    "FaceSurface": "geometry.face_surface",
    "Part": "geometry.part", "SharedEdge": "geometry.part", "load_step": "geometry.part",
    "Stepper": "interp.stepper", "Tangency": "interp.stepper",
    "intersection_path": "ops.path.pair_path", "intersection_paths": "ops.path.pair_path",
    "make_stepper": "ops.path.pair_path", "path_for_job": "ops.path.pair_path",
    "Toolpath": "program.toolpath",
    "VerificationReport": "verification", "verify": "verification",
    "gouge_gate": "verification",
    "pencil": "ops.pencil.setups", "finish": "ops.finish.finish", "Program": "program.program",
    "to_cq": "io.program_cq", "to_cq_compound": "io.program_cq",
    "show_program": "io.program_cq",
    "run": "ops.run", "program_for_job": "ops.path.pair_program",
    "pencil_program": "ops.pencil.pencil", "finish_program": "ops.finish.finish",
    "gate_program": "verification", "read_program": "io.program_json",
    "BatchPart": "batch.task", "BatchOperation": "batch.task", "Settings": "pipeline.operate",
    "run_batch": "batch.engine",
}

__all__ = [
    "CadcncError", "FaceNumberError", "FacePairError", "GeometryError", "InputError",
    "OutputError", "SingularPointError", "StartPointError", "StepFileError", "Job",
    "PairPath", "Pencil", "Finish", "Tool", "Tolerances", *_LAZY,
]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'cadcnc' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
