"""The operation records: what one operation of a :class:`~cadcnc.core.job.Job` cuts.

One frozen, validated record per operation: :class:`PairPath` (the path along the
intersection of two faces), :class:`Pencil` (every inner corner of a part), and the three
finishing strategies, :class:`Raster` (vertical guide planes), :class:`Waterline`
(horizontal levels) and :class:`SteepShallow` (waterline on the steep, raster on the
shallow). Each holds only its own fields; the planner of each record is registered in
:mod:`cadcnc.ops.operations`. A finishing record is written to a program's JSON as
``operation: "finish"`` with its ``strategy`` and every finishing field (the format's
keys: :meth:`Finishing.to_inputs`), and read back by :func:`finishing`. docs/finish.md,
docs/waterline.md. Lengths mm, angles degrees.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields
from typing import ClassVar

from .errors import InputError
from .tool import Tool
from .units import Point, check_faces, check_number, check_point, shown


@dataclass(frozen=True)
class PairPath:
    """The ``path`` operation: the ball follows the intersection of two offset surfaces.

    ``faces``: the two face numbers of the part (None for a face given directly).
    ``offsets``: each surface's offset, None meaning R'; 0 makes that surface a guide
    surface carrying the ball centre. ``start``/``end``: points (mm) near the intersection;
    by default the ends of the faces' shared concave edge number ``edge`` (0-based).
    A program of the pair (:func:`cadcnc.ops.path.pair_program.program_for_job`) follows every
    feasible stretch of every shared concave edge, or of edge ``edge`` alone when it is
    given (None: every edge), and of those only stretch number ``stretch`` (1-based along
    the edge) when given.
    """

    faces: tuple[int | None, int | None] = (None, None)
    offsets: tuple[float | None, float | None] = (None, None)
    start: Point | None = None
    end: Point | None = None
    edge: int | None = 0
    stretch: int | None = None

    def __post_init__(self):
        try:
            faces = tuple(self.faces)
        except TypeError:
            faces = ()
        if len(faces) != 2:
            raise InputError(f"a path needs two faces, got {shown(self.faces)}")
        for n in faces:
            if n is not None and (isinstance(n, bool) or not isinstance(n, numbers.Integral)
                                  or n < 1):
                raise InputError(f"face numbers are integers from 1, got {shown(n)}")
        object.__setattr__(self, "faces", tuple(None if n is None else int(n) for n in faces))
        offsets = tuple(self.offsets) if self.offsets is not None else (None, None)
        if len(offsets) != 2:
            raise InputError(f"offsets needs one value per surface, got {shown(self.offsets)}")
        object.__setattr__(self, "offsets", tuple(
            None if o is None else check_number("offset", o, "mm", allow_zero=True)
            for o in offsets))
        object.__setattr__(self, "start", check_point("start", self.start))
        object.__setattr__(self, "end", check_point("end", self.end))
        if self.end is not None and self.start is None:
            raise InputError("an end point needs a start point too")
        if self.edge is not None:
            if isinstance(self.edge, bool) or not isinstance(self.edge, numbers.Integral) \
                    or self.edge < 0:
                raise InputError(f"edge must be an index >= 0 among the shared concave "
                                 f"edges (or None: every edge), got {shown(self.edge)}")
            object.__setattr__(self, "edge", int(self.edge))
        if self.stretch is not None:
            if isinstance(self.stretch, bool) or not isinstance(
                    self.stretch, numbers.Integral) or self.stretch < 1:
                raise InputError(f"stretch numbers start at 1, got {shown(self.stretch)}")
            object.__setattr__(self, "stretch", int(self.stretch))

    def resolved_offsets(self, tool: Tool) -> tuple[float, float]:
        """Each surface's offset in mm, None resolved to the tool's R'."""
        return tuple(tool.offset if o is None else o for o in self.offsets)

    def describe(self) -> str:
        """The operation in a program's summary."""
        return f"path along faces {self.faces[0]} and {self.faces[1]}"

    def to_inputs(self) -> dict:
        return dict(operation="path", faces=list(self.faces),
                    start=None if self.start is None else list(self.start),
                    end=None if self.end is None else list(self.end), edge=self.edge,
                    stretch=self.stretch)


SIDES = ("climb", "conventional")


@dataclass(frozen=True)
class Pencil:
    """The ``pencil`` operation: every inner corner of the part a ball can clean.

    ``faces``: only corners whose two faces are among these numbers (None: every corner);
    ``side``: "climb" (the material on the right of the travel, for a clockwise spindle)
    or "conventional".
    """

    faces: tuple[int, ...] | None = None
    side: str = "climb"

    def __post_init__(self):
        if self.faces is not None:   # a set of faces: the same record whatever its order
            object.__setattr__(self, "faces", tuple(sorted(check_faces(self.faces))))
        if self.side not in SIDES:
            raise InputError(f"side must be one of {', '.join(SIDES)}, got "
                             f"{shown(self.side)}")

    def resolved_offsets(self, tool: Tool) -> tuple[float, float]:
        """(R', R'): the ball touches both faces of every corner."""
        return (tool.offset, tool.offset)

    def describe(self) -> str:
        """The operation in a program's summary."""
        which = "every corner" if self.faces is None else \
            "corners of faces " + " ".join(map(str, self.faces))
        return f"pencil, {which}, {self.side}"

    def to_inputs(self) -> dict:
        return dict(operation="pencil",
                    faces=None if self.faces is None else list(self.faces), side=self.side)


FINISH_PATTERNS = ("zigzag", "oneway")
FINISH_FIELDS = dict(stepover=None, scallop=None, angle=0.0, pattern="zigzag", stepdown=None,
                     threshold=45.0, side="climb", overlap=0.0)
"""Every finishing field with its default, in the order a program's JSON records them
(``strategy`` between ``stepdown`` and ``threshold``)."""
SPACINGS = ("stepover", "scallop", "stepdown")


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


def _angle(value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or \
            not math.isfinite(value):
        raise InputError(f"angle must be a finite number of degrees, got {shown(value)}")
    return float(value)


def _choice(name: str, value, allowed: tuple[str, ...]) -> str:
    if value not in allowed:
        raise InputError(f"{name} must be one of {', '.join(allowed)}, got {shown(value)}")
    return value


class Finishing:
    """What the finishing records share: ``faces`` (1-based numbers, at least one), the
    offsets (R', 0): the faces at the tool's offset, a guide surface carrying the centre,
    and the program JSON's keys. Subclasses name their ``strategy`` and ``NEEDS``: the
    sets of spacings (stepover, scallop, stepdown) that may be given together."""

    strategy: ClassVar[str]
    NEEDS: ClassVar[tuple[tuple[frozenset, ...], str]]

    def __post_init__(self):
        """Validate and normalise every field in place (the records' dataclass calls it)."""
        if isinstance(self.faces, (tuple, list)) and not self.faces:
            raise InputError("finishing needs at least one face")
        self._set("faces", check_faces(self.faces))
        if "side" in self._names():
            _choice("side", self.side, SIDES)
        if getattr(self, "stepdown", None) is not None:
            self._set("stepdown", _real("stepdown", self.stepdown, "mm", 0.0))
        if "overlap" in self._names():
            self._set("overlap", _real("overlap", self.overlap, "mm", 0.0, lo_open=False))
            self._set("threshold", _real("threshold", self.threshold, "degrees of slope",
                                         0.0, 90.0))
        self._check_spacings()
        for name in SPACINGS:
            if getattr(self, name, None) is not None:
                self._set(name, check_number(name, getattr(self, name), "mm"))
        if "angle" in self._names():
            self._set("angle", _angle(self.angle))
            _choice("pattern", self.pattern, FINISH_PATTERNS)

    def _check_spacings(self) -> None:
        check_spacings(self.strategy, {k: getattr(self, k, None) for k in SPACINGS})

    def _set(self, name: str, value) -> None:
        object.__setattr__(self, name, value)

    def _names(self) -> tuple[str, ...]:
        return tuple(f.name for f in fields(self))

    def resolved_offsets(self, tool: Tool) -> tuple[float, float]:
        """(R', 0): the faces at the tool's offset, the guide surface carrying the centre."""
        return (tool.offset, 0.0)

    def describe(self) -> str:
        """The operation in a program's summary: faces, strategy, spacing and the rest."""
        spacing = ", ".join(f"{k} {getattr(self, k):g} mm" for k in (
            "stepover", "stepdown", "scallop") if getattr(self, k, None) is not None)
        faces = " ".join(map(str, self.faces))
        if self.strategy == "raster":
            return f"finish faces {faces}, {spacing}, angle {self.angle:g} deg, {self.pattern}"
        how = (f"{self.side}" if self.strategy == "waterline" else
               f"threshold {self.threshold:g} deg, overlap {self.overlap:g} mm, {self.side}")
        return f"finish faces {faces}, {self.strategy}, {spacing}, {how}"

    def to_inputs(self) -> dict:
        """The program JSON's finishing keys: every field of FINISH_FIELDS (a field the
        strategy has not, at its default) and ``strategy``, in the format's order."""
        own = {k: getattr(self, k, default) for k, default in FINISH_FIELDS.items()}
        order = list(FINISH_FIELDS)
        order.insert(order.index("threshold"), "strategy")
        own["strategy"] = self.strategy
        return dict(operation="finish", faces=list(self.faces), **{k: own[k] for k in order})


def check_spacings(strategy: str, given: dict) -> None:
    """InputError unless the spacings given (``given``: stepover, scallop, stepdown, None
    where not given) are a set the ``strategy`` accepts (its record's NEEDS)."""
    options, need = FINISHING[strategy].NEEDS
    have = frozenset(k for k, v in given.items() if v is not None)
    if have not in options:
        raise InputError(f"finishing with strategy {strategy} needs {need}, got "
                         + (", ".join(f"{k} {given[k]!r}" for k in sorted(have)) or "none"))


@dataclass(frozen=True)
class Raster(Finishing):
    """Raster finishing: passes of the ball over ``faces``, its centre on vertical guide
    planes at ``angle`` degrees to +X. Exactly one of ``stepover`` (mm, the planes' fixed
    spacing) and ``scallop`` (mm, the largest scallop height the adaptive spacing allows);
    ``pattern`` "zigzag" (every other pass reversed, staying down where the move is
    verified clear) or "oneway" (every pass the same way, retracting between passes)."""

    faces: tuple[int, ...]
    stepover: float | None = None
    scallop: float | None = None
    angle: float = 0.0
    pattern: str = "zigzag"

    strategy: ClassVar[str] = "raster"
    NEEDS: ClassVar = ((frozenset({"stepover"}), frozenset({"scallop"})),
                       "stepover or scallop (stepdown is for waterline)")

    def _check_spacings(self) -> None:
        if (self.stepover is None) == (self.scallop is None):
            raise InputError("give exactly one of stepover (the planes' spacing, mm) and "
                             "scallop (the largest scallop height, mm)"
                             + ("" if self.stepover is None else
                                f", got stepover {shown(self.stepover)} and scallop "
                                f"{shown(self.scallop)}"))


@dataclass(frozen=True)
class Waterline(Finishing):
    """Waterline finishing: closed loops of the ball around ``faces`` on horizontal levels,
    top to bottom, ``stepdown`` mm apart or spaced for ``scallop`` (mm; exactly one);
    loops ``side`` "climb" or "conventional"."""

    faces: tuple[int, ...]
    stepdown: float | None = None
    scallop: float | None = None
    side: str = "climb"

    strategy: ClassVar[str] = "waterline"
    NEEDS: ClassVar = ((frozenset({"stepdown"}), frozenset({"scallop"})),
                       "exactly one of stepdown and scallop")


@dataclass(frozen=True)
class SteepShallow(Finishing):
    """Steep-and-shallow finishing: waterline where the slope exceeds ``threshold``
    degrees, raster elsewhere, the two regions overlapping ``overlap`` mm; ``scallop``
    alone, or ``stepover`` (the raster's) and ``stepdown`` (the waterline's). ``angle`` and
    ``pattern`` are the raster's, ``side`` the waterline loops'."""

    faces: tuple[int, ...]
    stepover: float | None = None
    stepdown: float | None = None
    scallop: float | None = None
    threshold: float = 45.0
    overlap: float = 0.0
    angle: float = 0.0
    pattern: str = "zigzag"
    side: str = "climb"

    strategy: ClassVar[str] = "steep-shallow"
    NEEDS: ClassVar = ((frozenset({"scallop"}), frozenset({"stepover", "stepdown"})),
                       "scallop alone, or both stepover (raster) and stepdown (waterline)")

    def raster(self) -> Raster:
        """The raster of the shallow region: the same faces, spacing, angle and pattern."""
        return Raster(self.faces, self.stepover, self.scallop, self.angle, self.pattern)


FINISHING: dict[str, type[Finishing]] = {
    r.strategy: r for r in (Raster, Waterline, SteepShallow)}
"""The finishing record of each strategy name (the CLI's ``--strategy``)."""
OPERATIONS = (PairPath, Pencil, Raster, Waterline, SteepShallow)
"""Every operation record a Job may hold."""


def _owners(name: str) -> str:
    """The strategies whose record has the field ``name``, for a message."""
    return " and ".join(s for s, kind in FINISHING.items()
                        if name in {f.name for f in fields(kind)})


def finishing(strategy: str, faces, *, own_only: bool = False, **given) -> Finishing:
    """The finishing record of ``strategy`` ("raster", "waterline", "steep-shallow") with
    ``given`` finishing fields (FINISH_FIELDS): a spacing the strategy has not (stepover,
    scallop, stepdown) is refused; the other fields it has not are left out (an old
    program's JSON gives every field), or, with ``own_only`` (what a user typed), refused
    by name rather than dropped."""
    kind = FINISHING.get(strategy)
    if kind is None:
        raise InputError(f"strategy must be one of {', '.join(FINISHING)}, got "
                         f"{shown(strategy)}")
    unknown = set(given) - set(FINISH_FIELDS)
    if unknown:
        raise InputError(f"finishing has no field {', '.join(sorted(unknown))}")
    own = {f.name for f in fields(kind)}
    foreign = sorted(k for k, v in given.items()
                     if v is not None and k not in own and k not in SPACINGS)
    if own_only and foreign:
        raise InputError(f"{strategy} finishing takes no {', '.join(foreign)} (a setting "
                         f"of {_owners(foreign[0])}); leave it out or change the strategy")
    if any(given.get(k) is not None for k in SPACINGS if k not in own):
        check_spacings(strategy, {k: given.get(k) for k in SPACINGS})
    return kind(faces, **{k: v for k, v in given.items() if k in own})
