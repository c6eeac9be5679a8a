"""The machine a program is streamed to: servo period and per-axis limits, and its INI file.

:class:`Machine` is validated where it is built (an :class:`~cadcnc.core.errors.InputError`
names the field); :func:`read_machine_ini` reads the limits from the LinuxCNC INI file a
user already has. Units inside: mm, s.
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.errors import InputError
from .ini_file import IniFile, leading_number

AXES = ("X", "Y", "Z")
INCH = 25.4  # mm
UNITS = {"mm": 1.0, "metric": 1.0, "millimeter": 1.0, "millimeters": 1.0,
         "in": INCH, "inch": INCH, "inches": INCH, "imperial": INCH}
"""LinuxCNC's spellings of ``[TRAJ] LINEAR_UNITS`` and their size in mm."""

DEFAULT_JERK_RAMP = 0.05
"""s: the default jerk reaches an axis's acceleration in this time (jerk = A / 0.05 s)."""


MAX_VELOCITY = 1e6       # mm/s: 1 km/s
MAX_ACCELERATION = 1e14  # mm/s^2
MAX_JERK = 1e20          # mm/s^3
MIN_PERIOD = 1e-6       # s: the shortest servo period accepted (1 us)
MAX_PERIOD = 0.1        # s: the longest (100 ms)
"""The largest limits a Machine takes: far beyond any machine tool ("no limit" in a test
is 1e6 mm/s, 1e14 mm/s², 1e20 mm/s³), and small enough that the planner's powers of them
(v^3, A^2, J^2...) stay finite (1e308 overflowed)."""


def _triple(name: str, value, unit: str, most: float) -> tuple[float, float, float]:
    """Three finite numbers in (0, most] (X, Y, Z), or InputError naming the field and the
    axis."""
    try:
        items = tuple(value)
    except TypeError:
        raise InputError(f"machine {name} must be three numbers (X Y Z) in {unit}, "
                         f"got {value!r}") from None
    if len(items) != 3:
        raise InputError(f"machine {name} must be three numbers (X Y Z) in {unit}, got "
                         f"{len(items)}")
    out = []
    for axis, v in zip(AXES, items):
        if (not isinstance(v, numbers.Real) or isinstance(v, bool)
                or not math.isfinite(float(v)) or not 0 < v <= most):
            raise InputError(f"machine {name} of axis {axis} must be a number > 0 {unit} "
                             f"and at most {most:g}, got {v!r}")
        out.append(float(v))
    return tuple(out)


@dataclass(frozen=True)
class Machine:
    """Servo ``period`` (s) and, per axis X Y Z, the largest velocity (mm/s),
    acceleration (mm/s²) and jerk (mm/s³); ``source`` says where the numbers come from."""

    period: float
    max_velocity: tuple[float, float, float]
    max_acceleration: tuple[float, float, float]
    max_jerk: tuple[float, float, float]
    source: str = ""

    def __post_init__(self):
        p = self.period
        if (not isinstance(p, numbers.Real) or isinstance(p, bool) or not math.isfinite(p)
                or not MIN_PERIOD <= p <= MAX_PERIOD):
            raise InputError(f"machine period must be a number of seconds in [1e-6, 0.1] "
                             f"(1 us .. 100 ms), got {p!r}")
        object.__setattr__(self, "period", float(p))
        for name, unit, most in (("max_velocity", "mm/s", MAX_VELOCITY),
                                 ("max_acceleration", "mm/s^2", MAX_ACCELERATION),
                                 ("max_jerk", "mm/s^3", MAX_JERK)):
            object.__setattr__(self, name, _triple(name, getattr(self, name), unit, most))
        object.__setattr__(self, "source", str(self.source))

    @classmethod
    def default(cls) -> "Machine":
        """A Tormach PCNC 770 (a small bench mill) as LinuxCNC 2.9 ships it:
        ``by_machine/tormach/pcnc-770.ini`` of the sample configurations (1 ms servo
        period; X, Y 2.25 in/s and 15 in/s²; Z 1.666 in/s and 10 in/s²). The INI has no
        jerk: ours reaches each axis's acceleration in 50 ms (DEFAULT_JERK_RAMP)."""
        v = (2.25 * INCH, 2.25 * INCH, 1.666 * INCH)
        a = (15 * INCH, 15 * INCH, 10 * INCH)
        return cls(0.001, v, a, tuple(x / DEFAULT_JERK_RAMP for x in a),
                   "Tormach PCNC 770 (LinuxCNC 2.9 sample config pcnc-770.ini), jerk A / 0.05 s")

    def limits(self) -> np.ndarray:
        """(3, 3) the velocity, acceleration and jerk limits (rows) per axis (columns)."""
        return np.array([self.max_velocity, self.max_acceleration, self.max_jerk],
                        dtype=np.float64)

    def summary(self) -> str:
        """One line: period and per-axis limits."""
        axes = ", ".join(f"{n} {v:g} mm/s {a:g} mm/s² {j:g} mm/s³" for n, v, a, j in zip(
            AXES, self.max_velocity, self.max_acceleration, self.max_jerk))
        return f"period {self.period * 1e3:g} ms; {axes}"


def _number(ini: IniFile, section: str, key: str, unit: str, warn) -> float:
    """[section] key as LinuxCNC reads it, a finite number > 0, or InputError naming file,
    section and key; what LinuxCNC ignores around it goes to ``warn``."""
    path = ini.path
    if not ini.has_section(section):
        raise InputError(f"{path}: section [{section}] is missing (needed for {key})")
    for text in ini.repeats(section, key):
        warn(text)
    raw, line = ini.find(section, key)
    if raw is None:
        raise InputError(f"{path}: [{section}] {key} is missing ({unit})")
    value, rest = leading_number(raw)
    if value is None:
        raise InputError(f"{line.where}: [{section}] {key} = {raw!r} is not a number ({unit})")
    if rest:
        warn(f"{line.where}: [{section}] {key} = {raw}: LinuxCNC reads the number {value:g} "
             f"and ignores {rest!r}, and so does cadcnc")
    if not math.isfinite(value) or value <= 0:
        raise InputError(f"{line.where}: [{section}] {key} = {raw} must be a number > 0 "
                         f"({unit})")
    return value


LIMITS = {"MAX_VELOCITY": ("units/s", MAX_VELOCITY, "mm/s"),
          "MAX_ACCELERATION": ("units/s^2", MAX_ACCELERATION, "mm/s^2"),
          "MAX_JERK": ("units/s^3", MAX_JERK, "mm/s^3")}


def _limit(ini: IniFile, section: str, key: str, scale: float, warn) -> float:
    """An axis limit in mm (``scale`` mm per unit), at most its bound (InputError)."""
    unit, most, mm = LIMITS[key]
    value = scale * _number(ini, section, key, unit, warn)
    if value > most:
        raise InputError(f"{ini.path}: [{section}] {key} = {value / scale:g} {unit} is over "
                         f"{most:g} {mm}, far beyond any machine: check the value")
    return value


def _warn(text: str) -> None:
    warnings.warn(text, IniWarning, stacklevel=3)


class IniWarning(UserWarning):
    """Something in a machine INI file LinuxCNC ignores (a repeated key or section, text
    after a number); cadcnc reads the value LinuxCNC reads."""


def read_machine_ini(path, jerk: float | None = None, warn=None) -> Machine:
    """The :class:`Machine` of a LinuxCNC INI file, every value read as LinuxCNC reads it
    (:mod:`.ini_file`: the first section and the first key win, ``#INCLUDE`` expanded).

    ``[EMCMOT] SERVO_PERIOD`` (ns), ``[TRAJ] LINEAR_UNITS`` (mm or inch), and per axis
    ``[AXIS_X]``, ``[AXIS_Y]``, ``[AXIS_Z]`` ``MAX_VELOCITY`` (units/s),
    ``MAX_ACCELERATION`` (units/s²) and ``MAX_JERK`` (units/s³) where present, else
    ``jerk`` (mm/s³, every axis). LinuxCNC 2.9 has no jerk key: without ``jerk`` that is
    an error naming the key. Missing or bad values: InputError naming file, section, key.
    What LinuxCNC ignores (a repeated key or section, text after a number) is reported to
    ``warn(text)`` (default: an :class:`IniWarning`), naming both lines.
    """
    path = Path(path)
    warn = _warn if warn is None else warn
    ini = IniFile(path)
    period_ns = _number(ini, "EMCMOT", "SERVO_PERIOD", "ns", warn)
    if not ini.has_section("TRAJ"):
        raise InputError(f"{path}: section [TRAJ] is missing (needed for LINEAR_UNITS)")
    for text in ini.repeats("TRAJ", "LINEAR_UNITS"):
        warn(text)
    units, line = ini.find("TRAJ", "LINEAR_UNITS")
    if units is None:
        raise InputError(f"{path}: [TRAJ] LINEAR_UNITS is missing (mm or inch)")
    scale = UNITS.get(units.lower())
    if scale is None:
        raise InputError(f"{line.where}: [TRAJ] LINEAR_UNITS = {units!r} is not a length "
                         f"unit LinuxCNC knows (one of {', '.join(UNITS)})")
    if jerk is not None:
        jerk = _triple("jerk (--jerk)", (jerk,) * 3, "mm/s^3", MAX_JERK)[0]
    v, a, j = [], [], []
    for axis in AXES:
        section = f"AXIS_{axis}"
        v.append(_limit(ini, section, "MAX_VELOCITY", scale, warn))
        a.append(_limit(ini, section, "MAX_ACCELERATION", scale, warn))
        if ini.find(section, "MAX_JERK")[0] is not None:
            j.append(_limit(ini, section, "MAX_JERK", scale, warn))
        elif jerk is not None:
            j.append(jerk)
        else:
            raise InputError(f"{path}: [{section}] MAX_JERK is missing (LinuxCNC 2.9 has "
                             "none): give the jerk with --jerk MM/S3")
    try:
        period = Machine(period_ns * 1e-9, (1.0,) * 3, (1.0,) * 3, (1.0,) * 3).period  # ns -> s
    except InputError as e:
        raise InputError(f"{path}: [EMCMOT] SERVO_PERIOD = {period_ns:g} ns: {e}") from None
    try:
        return Machine(period, tuple(v), tuple(a), tuple(j), str(path))
    except InputError as e:
        raise InputError(f"{path}: {e} (the INI's values in mm)") from None
