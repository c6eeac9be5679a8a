"""cadcnc: direct interpolation of ball-end cutter paths along the intersection of two faces.

The public API (docs/api.md): a part (:class:`Part`, :func:`load_step`), a job
(:class:`Job`, :class:`Tool` and one operation record: :class:`PairPath`,
:class:`Pencil`, :class:`Raster`, :class:`Waterline`, :class:`SteepShallow`), the one way
to run every operation (:func:`run`; :func:`finish`, the finishing shortcut of a CadQuery
script), the :class:`Program` it returns (:func:`read_program`), the gate
(:func:`gate_program`), CQ-editor (:func:`show_program`), the real-time stepper
(:func:`make_stepper`), the stock simulation (:func:`simulate`) and the errors' root (:class:`CadcncError`, :class:`InputError`).
Everything else is in its stage's module (docs/architecture.md). Units: mm, mm/min, s.

The names that need OCCT are loaded on first use: importing OCCT takes about 1.5 s, which
``import cadcnc`` (and ``cadcnc --help``) should not pay before it is needed.
"""

from __future__ import annotations

import importlib

from .core.errors import CadcncError, InputError
from .core.job import Job, PairPath, Pencil, Raster, SteepShallow, Tool, Waterline

__version__ = "0.1.0"

_LAZY = {
    "Part": "geometry.part", "load_step": "geometry.part",
    "run": "ops.run", "finish": "ops.finish.shortcut",
    "Program": "program.program", "read_program": "io.program_json",
    "gate_program": "verification", "show_program": "io.program_cq",
    "make_stepper": "ops.path.pair_path", "simulate": "simulation.simulator",
}

__all__ = ["CadcncError", "InputError", "Job", "Tool", "PairPath", "Pencil", "Raster",
           "Waterline", "SteepShallow", *_LAZY]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'cadcnc' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
