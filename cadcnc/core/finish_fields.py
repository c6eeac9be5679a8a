"""The finishing strategies' fields of a :class:`~cadcnc.core.job.Finish`, validated once.

``strategy``: raster (vertical guide planes, ``stepover`` or ``scallop``), waterline
(horizontal levels ``stepdown`` mm apart, or spaced for ``scallop``; loops ``side`` climb
or conventional) or steep-shallow (waterline where the slope exceeds ``threshold`` deg,
raster elsewhere, the two regions overlapping ``overlap`` mm; ``scallop`` alone, or
``stepover`` and ``stepdown``). docs/finish.md. Lengths mm, angles degrees.
"""

from __future__ import annotations

import math
import numbers

from .errors import InputError

FINISH_STRATEGIES = ("raster", "waterline", "steep-shallow")
LOOP_SIDES = ("climb", "conventional")
NEEDS = {
    "raster": ([{"stepover"}, {"scallop"}], "stepover or scallop (stepdown is for waterline)"),
    "waterline": ([{"stepdown"}, {"scallop"}], "exactly one of stepdown and scallop"),
    "steep-shallow": ([{"scallop"}, {"stepover", "stepdown"}],
                      "scallop alone, or both stepover (raster) and stepdown (waterline)"),
}


def _real(name: str, value, unit: str, lo: float, hi: float = math.inf,
          lo_open: bool = True) -> float:
    """``value`` as a float within (lo, hi) (``[lo, hi)`` unless ``lo_open``), or an
    InputError naming ``name`` and its unit."""
    good = isinstance(value, numbers.Real) and not isinstance(value, bool) and (
        lo < value < hi if lo_open else lo <= value < hi)
    if not good:
        span = f"{'>' if lo_open else '>='} {lo:g}" + ("" if hi == math.inf else
                                                        f" and < {hi:g}")
        raise InputError(f"{name} must be a number {span} {unit}, got {value!r}")
    return float(value)


def check_strategy(op) -> None:
    """Validate the strategy fields of the Finish ``op`` in place (module doc); the
    raster checks of stepover and scallop stay the Finish's own."""
    for name, allowed in (("strategy", FINISH_STRATEGIES), ("side", LOOP_SIDES)):
        if getattr(op, name) not in allowed:
            raise InputError(f"{name} must be one of {', '.join(allowed)}, got "
                             f"{getattr(op, name)!r}")
    if op.stepdown is not None:
        object.__setattr__(op, "stepdown", _real("stepdown", op.stepdown, "mm", 0.0))
    object.__setattr__(op, "overlap", _real("overlap", op.overlap, "mm", 0.0, lo_open=False))
    object.__setattr__(op, "threshold", _real("threshold", op.threshold,
                                              "degrees of slope", 0.0, 90.0))
    given = {k for k in ("stepover", "stepdown", "scallop") if getattr(op, k) is not None}
    options, need = NEEDS[op.strategy]
    if op.strategy == "raster" and "stepdown" not in given:
        return   # the Finish's own check: exactly one of stepover and scallop
    if given not in options:
        raise InputError(f"finishing with strategy {op.strategy} needs {need}, got "
                         + (", ".join(f"{k} {getattr(op, k)!r}" for k in sorted(given))
                            or "none"))
