"""Parse the quantities users type: durations with a unit, lengths, feeds and points.

Internally cadcnc works in mm, mm/min and s (docs/method.md). A period must carry its
unit (``4ms``, ``0.004s``, ``250us``) because a bare ``4`` is ambiguous; lengths may carry
``mm`` and feeds ``mm/min``, nothing else. Every failure is an :class:`InputError` naming
the parameter and the unit it expects.
"""

from __future__ import annotations

import math
import numbers
import re

from .errors import InputError

_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_QUANTITY = re.compile(rf"^\s*({_NUMBER})\s*([A-Za-zµ/]*)\s*$")
_NON_FINITE = re.compile(r"^\s*[+-]?(?:inf(?:inity)?|nan)\b", re.IGNORECASE)
DURATION_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}  # seconds per unit


def _split(text: str, name: str, expected: str) -> tuple[float, str]:
    m = _QUANTITY.match(str(text))
    if not m:
        if _NON_FINITE.match(str(text)):
            raise InputError(f"{name}: {text!r} is not a finite number ({expected})")
        raise InputError(f"{name}: cannot read {text!r} as a number ({expected})")
    value = float(m.group(1))
    if not math.isfinite(value):
        raise InputError(f"{name}: {text!r} is not a finite number ({expected})")
    return value, m.group(2)


def parse_duration(text: str, name: str = "period") -> float:
    """Seconds from ``4ms``, ``0.004s``, ``250us`` (or ``250µs``); must be > 0."""
    expected = "give a unit: 4ms, 0.004s or 250us"
    value, unit = _split(text, name, expected)
    if not unit:
        raise InputError(f"{name}: {text!r} has no unit; {expected}")
    if unit not in DURATION_UNITS:
        raise InputError(f"{name}: unknown unit {unit!r} in {text!r}; {expected}")
    if value <= 0:
        raise InputError(f"{name} must be > 0, got {text!r}")
    return value * DURATION_UNITS[unit]


def parse_length(text: str, name: str, allow_zero: bool = True) -> float:
    """Millimetres from ``3`` or ``3mm``; must be >= 0 (> 0 unless ``allow_zero``)."""
    value, unit = _split(text, name, "a length in mm")
    if unit not in ("", "mm"):
        raise InputError(f"{name}: lengths are in mm, got unit {unit!r} in {text!r}")
    if value < 0 or (value == 0 and not allow_zero):
        raise InputError(f"{name} must be {'>=' if allow_zero else '>'} 0 mm, got {text!r}")
    return value


def parse_feed(text: str, name: str = "feed") -> float:
    """mm/min from ``1500`` or ``1500mm/min``; must be > 0."""
    value, unit = _split(text, name, "a feed in mm/min")
    if unit not in ("", "mm/min"):
        raise InputError(f"{name}: feeds are in mm/min, got unit {unit!r} in {text!r}")
    if value <= 0:
        raise InputError(f"{name} must be > 0 mm/min, got {text!r}")
    return value


def parse_point(text: str, name: str) -> tuple[float, float, float]:
    """A point ``X,Y,Z`` in mm (spaces allowed)."""
    parts = [p for p in re.split(r"[,\s]+", str(text).strip()) if p]
    if len(parts) != 3:
        raise InputError(f"{name}: expected X,Y,Z in mm, got {text!r}")
    try:
        xyz = tuple(float(p) for p in parts)
    except ValueError:
        raise InputError(f"{name}: expected X,Y,Z in mm, got {text!r}") from None
    if not all(math.isfinite(v) for v in xyz):
        raise InputError(f"{name}: coordinates must be finite, got {text!r}")
    return xyz


def format_duration(seconds: float) -> str:
    """``4 ms``, ``250 us``, ``1.5 s``: the largest unit that keeps the number >= 1."""
    for unit, scale in ((u, DURATION_UNITS[u]) for u in ("s", "ms", "us")):
        if abs(seconds) >= scale:
            return f"{seconds / scale:g} {unit}"
    return f"{seconds:g} s"


PRINCIPAL_AXES = {"+X": (1.0, 0.0, 0.0), "-X": (-1.0, 0.0, 0.0), "+Y": (0.0, 1.0, 0.0),
                  "-Y": (0.0, -1.0, 0.0), "+Z": (0.0, 0.0, 1.0), "-Z": (0.0, 0.0, -1.0)}
"""The six principal tool axes by name (the axis points from the ball centre up the shank)."""


def check_axis(value) -> tuple[float, float, float]:
    """A tool axis as a unit (x, y, z) tuple: one of PRINCIPAL_AXES' names (``Z`` is
    ``+Z``) or a finite non-zero vector (normalised), as a sequence or "x,y,z"."""
    if isinstance(value, str):
        name = value.strip().upper()
        name = name if name[:1] in "+-" else "+" + name
        if name in PRINCIPAL_AXES:
            return PRINCIPAL_AXES[name]
        if "," not in value:
            raise InputError(f"axis must be one of {', '.join(PRINCIPAL_AXES)} or a vector "
                             f"x,y,z, got {value!r}")
        value = value.split(",")
    try:
        xyz = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        xyz = ()
    norm = math.sqrt(sum(v * v for v in xyz)) if len(xyz) == 3 else math.nan
    if not (math.isfinite(norm) and norm > 0):
        raise InputError(f"axis must be one of {', '.join(PRINCIPAL_AXES)} or a finite "
                         f"non-zero vector (x, y, z), got {value!r}")
    return tuple(v / norm + 0.0 for v in xyz)


def axis_name(axis) -> str:
    """"+Z", "-X", ... for a principal axis, else its components."""
    for name, xyz in PRINCIPAL_AXES.items():
        if tuple(axis) == xyz:
            return name
    return "(" + ", ".join(f"{v:.6g}" for v in axis) + ")"


Point = tuple[float, float, float]


def check_number(name: str, value, unit: str, *, allow_zero: bool = False) -> float:
    """``value`` as a float if it is a real finite number > 0 (>= 0 with ``allow_zero``).

    Booleans are refused (``radius=True`` is a mistake, not 1 mm); numpy scalars are
    numbers. The error names the parameter and its unit.
    """
    ok = (isinstance(value, numbers.Real) and not isinstance(value, bool)
          and math.isfinite(float(value)))
    if not ok or value < 0 or (value == 0 and not allow_zero):
        need = ">= 0" if allow_zero else "> 0"
        raise InputError(f"{name} must be a number {need} {unit}, got {shown(value)}")
    return float(value)


def check_point(name: str, value) -> Point | None:
    """A point (x, y, z) in mm as a float tuple, or None."""
    if value is None:
        return None
    try:
        xyz = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        xyz = ()
    if isinstance(value, (str, bytes)) or len(xyz) != 3 or not all(map(math.isfinite, xyz)):
        raise InputError(f"{name} must be a point (x, y, z) in mm, got {shown(value)}")
    return xyz


def shown(value) -> str:
    """A value as a user reads it: plain numbers, not numpy reprs."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return f"{float(value):g}"
    return repr(value)


def check_faces(faces) -> tuple[int, ...]:
    """Face numbers (integers from 1) as a tuple, each once, in the order given."""
    try:
        items = tuple(faces)
    except TypeError:
        raise InputError(f"faces must be face numbers, got {shown(faces)}") from None
    if not items:
        raise InputError("no face given: give at least one face number")
    for n in items:
        if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1:
            raise InputError(f"face numbers are integers from 1, got {shown(n)}")
    return tuple(dict.fromkeys(int(n) for n in items))
