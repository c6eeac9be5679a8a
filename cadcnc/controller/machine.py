"""The machine a program is streamed to: servo period and per-axis limits, and its INI file.

:class:`Machine` is validated where it is built (an :class:`~cadcnc.errors.InputError`
names the field); :func:`read_machine_ini` reads the limits from the LinuxCNC INI file a
user already has. Units inside: mm, s.
"""

from __future__ import annotations

import configparser
import math
import numbers
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

AXES = ("X", "Y", "Z")
INCH = 25.4  # mm
UNITS = {"mm": 1.0, "metric": 1.0, "millimeter": 1.0, "millimeters": 1.0,
         "in": INCH, "inch": INCH, "inches": INCH, "imperial": INCH}
"""LinuxCNC's spellings of ``[TRAJ] LINEAR_UNITS`` and their size in mm."""

DEFAULT_JERK_RAMP = 0.05
"""s: the default jerk reaches an axis's acceleration in this time (jerk = A / 0.05 s)."""


def _triple(name: str, value, unit: str) -> tuple[float, float, float]:
    """Three finite numbers > 0 (X, Y, Z), or InputError naming the field and the axis."""
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
                or not math.isfinite(float(v)) or v <= 0):
            raise InputError(f"machine {name} of axis {axis} must be a number > 0 {unit}, "
                             f"got {v!r}")
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
                or not 1e-6 <= p <= 0.1):
            raise InputError(f"machine period must be a number of seconds in [1e-6, 0.1] "
                             f"(1 us .. 100 ms), got {p!r}")
        object.__setattr__(self, "period", float(p))
        for name, unit in (("max_velocity", "mm/s"), ("max_acceleration", "mm/s^2"),
                           ("max_jerk", "mm/s^3")):
            object.__setattr__(self, name, _triple(name, getattr(self, name), unit))
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

    def summary(self) -> str:
        """One line: period and per-axis limits."""
        axes = ", ".join(f"{n} {v:g} mm/s {a:g} mm/s² {j:g} mm/s³" for n, v, a, j in zip(
            AXES, self.max_velocity, self.max_acceleration, self.max_jerk))
        return f"period {self.period * 1e3:g} ms; {axes}"


def _parser(path: Path) -> configparser.ConfigParser:
    ini = configparser.ConfigParser(strict=False, interpolation=None,
                                    comment_prefixes=("#", ";"), inline_comment_prefixes=None)
    ini.optionxform = str   # LinuxCNC's keys are case-sensitive upper case
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as e:
        raise InputError(f"{path}: cannot read the machine INI file ({e.strerror or e})") \
            from None
    try:
        ini.read_string(text, source=str(path))
    except configparser.Error as e:
        first = str(e).splitlines()[0]
        raise InputError(f"{path}: not a LinuxCNC INI file ({first})") from None
    return ini


def _number(ini, path: Path, section: str, key: str, unit: str) -> float:
    """[section] key as a finite number > 0, or InputError naming file, section and key."""
    if not ini.has_section(section):
        raise InputError(f"{path}: section [{section}] is missing (needed for {key})")
    raw = ini.get(section, key, fallback=None)
    if raw is None or not raw.strip():
        raise InputError(f"{path}: [{section}] {key} is missing ({unit})")
    try:
        value = float(raw.strip())
    except ValueError:
        raise InputError(f"{path}: [{section}] {key} = {raw.strip()!r} is not a number "
                         f"({unit})") from None
    if not math.isfinite(value) or value <= 0:
        raise InputError(f"{path}: [{section}] {key} = {raw.strip()} must be a number > 0 "
                         f"({unit})")
    return value


def read_machine_ini(path, jerk: float | None = None) -> Machine:
    """The :class:`Machine` of a LinuxCNC INI file.

    ``[EMCMOT] SERVO_PERIOD`` (ns), ``[TRAJ] LINEAR_UNITS`` (mm or inch), and per axis
    ``[AXIS_X]``, ``[AXIS_Y]``, ``[AXIS_Z]`` ``MAX_VELOCITY`` (units/s),
    ``MAX_ACCELERATION`` (units/s²) and ``MAX_JERK`` (units/s³) where present, else
    ``jerk`` (mm/s³, every axis). LinuxCNC 2.9 has no jerk key: without ``jerk`` that is
    an error naming the key. Missing or bad values: InputError naming file, section, key.
    """
    path = Path(path)
    ini = _parser(path)
    period_ns = _number(ini, path, "EMCMOT", "SERVO_PERIOD", "ns")
    units = ini.get("TRAJ", "LINEAR_UNITS", fallback=None) if ini.has_section("TRAJ") else None
    if units is None:
        raise InputError(f"{path}: [TRAJ] LINEAR_UNITS is missing (mm or inch)")
    scale = UNITS.get(units.strip().lower())
    if scale is None:
        raise InputError(f"{path}: [TRAJ] LINEAR_UNITS = {units.strip()!r} is not a length "
                         f"unit LinuxCNC knows (one of {', '.join(UNITS)})")
    if jerk is not None:
        jerk = _triple("jerk (--jerk)", (jerk,) * 3, "mm/s^3")[0]
    v, a, j = [], [], []
    for axis in AXES:
        section = f"AXIS_{axis}"
        v.append(scale * _number(ini, path, section, "MAX_VELOCITY", "units/s"))
        a.append(scale * _number(ini, path, section, "MAX_ACCELERATION", "units/s^2"))
        if ini.has_option(section, "MAX_JERK"):
            j.append(scale * _number(ini, path, section, "MAX_JERK", "units/s^3"))
        elif jerk is not None:
            j.append(jerk)
        else:
            raise InputError(f"{path}: [{section}] MAX_JERK is missing (LinuxCNC 2.9 has "
                             "none): give the jerk with --jerk MM/S3")
    try:
        return Machine(period_ns * 1e-9, tuple(v), tuple(a), tuple(j), str(path))
    except InputError as e:
        raise InputError(f"{path}: [EMCMOT] SERVO_PERIOD = {period_ns:g} ns: {e}") from None
