"""A setup: the part clamped so that a chosen tool axis points up the machine's +Z.

Every operation works along +Z. For another tool axis ``a`` (a unit vector in part
coordinates, pointing from the ball centre up the shank) the part is turned rigidly so
that ``a`` becomes +Z, the operation runs unchanged on the turned part, and what it
returns is in the setup's work coordinates (the G-code's)::

    q = R (p - o)        p = R^T q + o

with ``R`` (3, 3) the rotation (rows: the machine's X, Y, Z in part coordinates, so
``R a = +Z``) and ``o`` (3,) the work zero in part coordinates: by default the centre of
the part's top seen along the axis (the middle of its box across the axis, its highest
point along it). The default axis +Z without a given origin is the identity (part
coordinates, as always). ``R = Ry(B) Rx(A)``: turning the part by A about X, then by B
about Y (right-handed, degrees) brings the axis up, which is what an indexing table's
A/B angles give. Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.gp import gp_Trsf

from ..core.errors import OutputError
from ..core.job import PRINCIPAL_AXES, Job, axis_name
from .boxes import optimal_box
from .part import Part

SAME_ROTATION = 1e-12  # per entry: two rotations this close are one (round-off of cos, sin)
SAME_ORIGIN = 1e-9     # mm: two setup origins this close are one


def rotation_for(axis) -> np.ndarray:
    """(3, 3) R = Ry(B) Rx(A) with R @ axis = +Z (see :func:`table_angles`)."""
    a, b = table_angles(axis)
    ca, sa, cb, sb = (math.cos(math.radians(a)), math.sin(math.radians(a)),
                      math.cos(math.radians(b)), math.sin(math.radians(b)))
    rx = np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])
    ry = np.array([[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]])
    r = ry @ rx
    r[np.abs(r) < 1e-15] = 0.0   # principal axes: exact 0 and +-1
    return r


def table_angles(axis) -> tuple[float, float]:
    """(A, B) degrees: turning the part by A about X, then B about Y, brings ``axis`` up."""
    x, y, z = (float(v) for v in axis)
    a = math.degrees(math.atan2(y, z)) if (y or z) else 0.0
    b = math.degrees(math.atan2(-x, math.hypot(y, z)))
    return a, b


@dataclass(frozen=True, eq=False)
class Setup:
    """The tool ``axis`` (3,), ``rotation`` R (3, 3) and work zero ``origin`` (3,), part
    coordinates, mm (module doc)."""

    axis: np.ndarray
    rotation: np.ndarray
    origin: np.ndarray

    @property
    def identity(self) -> bool:
        return bool(np.array_equal(self.rotation, np.eye(3)) and not np.any(self.origin))

    @property
    def name(self) -> str:
        """"+Z", "-X", ... or the vector's components."""
        return axis_name(tuple(self.axis))

    def to_setup(self, points) -> np.ndarray:
        """(..., 3) part coordinates to the setup's work coordinates."""
        return (np.asarray(points, float) - self.origin) @ self.rotation.T

    def to_part(self, points) -> np.ndarray:
        """(..., 3) work coordinates back to part coordinates."""
        return np.asarray(points, float) @ self.rotation + self.origin

    def to_dict(self) -> dict:
        """The program JSON's ``setup`` object."""
        return dict(axis=self.axis.tolist(), rotation=self.rotation.tolist(),
                    origin=self.origin.tolist())

    def describe(self) -> list[str]:
        """Short sentences for a summary and the G-code's comments: the axis, the work
        zero, the rotation from part coordinates and, for a non-principal axis, the
        indexing table's angles."""
        a, b = table_angles(self.axis)
        o = ", ".join(f"{v:.3f}" for v in self.origin)
        rows = "; ".join(" ".join(f"{v:.6g}" for v in row) for row in self.rotation)
        lines = [f"tool axis {self.name} (part coordinates) is the machine's +Z",
                 f"work zero at part ({o}) mm",
                 f"work = R (part - zero), R rows [{rows}]"]
        if self.name not in PRINCIPAL_AXES:
            lines.append(f"an indexing table gives it: turn the part A {a:.3f} deg about "
                         f"X, then B {b:.3f} deg about Y")
        return lines

    @classmethod
    def from_dict(cls, d: dict) -> "Setup":
        return cls(*(np.asarray(d[k], float) for k in ("axis", "rotation", "origin")))


def _moved(shape, rotation: np.ndarray, shift: np.ndarray):
    """A copy of ``shape`` with every point p moved to rotation @ p + shift."""
    t = gp_Trsf()
    r, s = rotation, shift
    t.SetValues(*r[0], s[0], *r[1], s[1], *r[2], s[2])
    return BRepBuilderAPI_Transform(shape, t, True).Shape()


class SetupPart(Part):
    """The part turned into a setup's work coordinates; ``setup`` and the ``original``
    part (in part coordinates) are kept for the outputs. Face numbers are the original's."""

    def __init__(self, original: Part, setup: Setup, shape):
        super().__init__(shape, source=original.source, tol=original.tol,
                         flip_material=original.flip_material)
        self.setup = setup
        self.original = original
        self.warnings = list(original.warnings)


def setup_of(part: Part, axis, origin=None) -> Setup:
    """The :class:`Setup` of ``axis`` on ``part``: work zero ``origin`` (part coordinates)
    or the centre of the part's top seen along the axis (identity for +Z without one).
    The top's box (OCCT's optimal box of the turned shape, about 0.4 s on a part of 100
    faces) is kept on the part by axis: every gate of a setup's cut asks again."""
    axis = np.asarray(axis, float)
    rot = rotation_for(axis)
    if origin is not None:
        return Setup(axis, rot, np.asarray(origin, float))
    if np.array_equal(rot, np.eye(3)):
        return Setup(axis, rot, np.zeros(3))
    tops = part.derived.setdefault(f"{__name__}.top", {})   # by axis: the top, work zero
    key = tuple(axis)
    if key not in tops:
        lo, hi = optimal_box(_moved(part.given_shape, rot, np.zeros(3)),
                             use_triangulation=True)
        tops[key] = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2]]) @ rot
    return Setup(axis, rot, tops[key].copy())


def setup_part(part: Part, job: Job | Setup) -> Part:
    """``part`` in the setup of ``job`` (its axis and origin) or of a given Setup: the part
    itself for the identity, else a cached :class:`SetupPart`. A SetupPart of that setup
    is returned as is; one of another setup is turned from its original."""
    if isinstance(part, SetupPart):
        if isinstance(job, Setup) and _same(part.setup, job):
            return part
        if isinstance(job, Job) and _same(part.setup, setup_of(part.original, job.axis,
                                                               job.origin)):
            return part
        part = part.original
    setup = job if isinstance(job, Setup) else setup_of(part, job.axis, job.origin)
    if setup.identity:
        return part
    cache = part.derived.setdefault(__name__, {})   # the part's turned copies
    key = (tuple(setup.rotation.ravel()), tuple(setup.origin))
    if key not in cache:
        shape = _moved(part.given_shape, setup.rotation, -setup.rotation @ setup.origin)
        cache[key] = SetupPart(part, setup, shape)
    return cache[key]


def setup_in(part) -> Setup | None:
    """The setup a part was turned into (None: part coordinates)."""
    return part.setup if isinstance(part, SetupPart) else None


def job_setup(job: Job, part) -> Setup | None:
    """The setup of ``job`` on ``part`` (None: part coordinates, the default +Z without a
    work zero); OutputError when another setup is asked for without the part."""
    if job.axis == PRINCIPAL_AXES["+Z"] and job.origin is None:
        return None
    if part is None:
        raise OutputError("a program of another tool axis than +Z (or with a work zero) "
                          "needs its part to be written")
    return setup_in(setup_part(part, job))


def original_part(part):
    """The part in part coordinates (a SetupPart's original, else ``part``)."""
    return part.original if isinstance(part, SetupPart) else part


def _same(a: Setup, b: Setup) -> bool:
    return bool(np.allclose(a.rotation, b.rotation, atol=SAME_ROTATION)
                and np.allclose(a.origin, b.origin, atol=SAME_ORIGIN))
