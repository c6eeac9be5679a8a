"""What the user asked for: one typed, validated record per machining job.

A :class:`Job` holds what every operation shares (the part's source, the tool, feed,
plunge feed, spindle speed, period, clearance height, tolerances) and one operation record
(:mod:`cadcnc.core.operations`: :class:`PairPath`, the path along the intersection of two
faces; :class:`Pencil`, every inner corner of a part; :class:`Raster`, :class:`Waterline`
and :class:`SteepShallow`, the finishing strategies). It is
validated once, where it is built; everything downstream (the API, the toolpath, the
APT-like programs, the CLI, the JSON writer and reader) reads its fields, never string
keys. Units: lengths mm, feed mm/min, period s.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

from .errors import InputError
from .operations import (  # noqa: F401 - the records a Job holds, named where the Job is
    FINISH_FIELDS,
    FINISHING,
    OPERATIONS,
    SIDES,
    Finishing,
    PairPath,
    Pencil,
    Raster,
    SteepShallow,
    Waterline,
    finishing,
)
from .tolerances import DEFAULT, Tolerances
from .tool import SHANK_LENGTH_RADII, Tool  # noqa: F401 - the Job's tool
from .units import (  # noqa: F401 - the Job's axis  # noqa: F401 - checks of every record
    PRINCIPAL_AXES,
    Point,
    axis_name,
    check_axis,
    check_faces,
    check_number,
    check_point,
    shown,
)

DEFAULT_FEED = 1500.0  # mm/min: with DEFAULT_PERIOD, the paper's 0.1 mm step
DEFAULT_PERIOD = 0.004  # s: the interpolation period
SAFE_MARGIN = 10.0  # mm above the part's top where links travel when no clearance is given
MIN_STEP = 1e-6  # mm: the shortest commanded step f = F Ts per period a job may ask for


def check_step(feed: float, period: float) -> float:
    """f = F Ts / 60 in mm, or InputError naming feed and period when it is below MIN_STEP.

    A step of a nanometre per period is a mistake (a period in the wrong unit), and a step
    that rounds to nothing never reaches the end: 1e6 cycles of nothing, or a closed path
    "completed" at its start.
    """
    f = feed * period / 60.0
    if not f >= MIN_STEP:
        raise InputError(f"feed {shown(feed)} mm/min and period {shown(period)} s give a "
                         f"step of {f:.3g} mm per period, below the minimum {MIN_STEP:g} mm: "
                         "raise the feed or the period (is the period in seconds?)")
    return f


@dataclass(frozen=True)
class Job:
    """One machining job: tool, feed (mm/min), period (s), operation, part, tolerances.

    ``source``: the part's STEP file (None for a CadQuery object). ``clearance``: the Z
    height (mm) of rapid moves, None for the part's top plus SAFE_MARGIN. ``flip_material``:
    the part is read with its material side inverted (``--flip-material``,
    docs/notes/surface_models.md), so that a saved path is verified on the same side.
    ``plunge_feed`` (mm/min): the feed of the links' plunges (None: the feed);
    ``spindle`` (rpm): written as ``S.. M3`` in the G-code (None: no spindle word).
    ``axis``: the tool axis in part coordinates (a unit vector from the ball centre up the
    shank; a name of PRINCIPAL_AXES or a vector), ``origin``: the work zero in part
    coordinates (None: the centre of the part's top seen along the axis; with +Z, the
    part's own origin): see :mod:`cadcnc.geometry.setup`. ``clearance`` is then a height
    in the setup's work coordinates.
    """

    tool: Tool
    feed: float
    period: float
    operation: PairPath | Pencil | Finishing = field(default_factory=PairPath)
    source: str | None = None
    clearance: float | None = None
    tolerances: Tolerances = DEFAULT
    flip_material: bool = False
    plunge_feed: float | None = None
    spindle: float | None = None
    axis: tuple[float, float, float] = PRINCIPAL_AXES["+Z"]
    origin: Point | None = None

    def __post_init__(self):
        object.__setattr__(self, "axis", check_axis(self.axis))
        object.__setattr__(self, "origin", check_point("origin", self.origin))
        object.__setattr__(self, "feed", check_number("feed", self.feed, "mm/min"))
        object.__setattr__(self, "period", check_number("period", self.period, "s"))
        check_step(self.feed, self.period)
        if self.clearance is not None:
            c = self.clearance
            if isinstance(c, bool) or not isinstance(c, numbers.Real) or not math.isfinite(c):
                raise InputError(f"clearance must be a finite height in mm, got {shown(c)}")
            object.__setattr__(self, "clearance", float(c))
        if self.source is not None:
            object.__setattr__(self, "source", str(self.source))
        for name, kinds in (("tool", (Tool,)), ("operation", OPERATIONS),
                            ("tolerances", (Tolerances,))):
            if not isinstance(getattr(self, name), kinds):
                names = " or ".join(k.__name__ for k in kinds)
                raise InputError(f"{name} must be a {names} record, got "
                                 f"{type(getattr(self, name)).__name__}")
        if self.plunge_feed is not None:
            object.__setattr__(self, "plunge_feed", check_number(
                "plunge feed", self.plunge_feed, "mm/min"))
        if self.spindle is not None:
            object.__setattr__(self, "spindle", check_number("spindle speed", self.spindle,
                                                             "rpm"))

    @property
    def step(self) -> float:
        """f = F Ts, mm: the commanded step per interpolation period."""
        return self.feed * self.period / 60.0

    @property
    def offsets(self) -> tuple[float, float]:
        """The operation's surface offsets resolved against the tool, mm."""
        return self.operation.resolved_offsets(self.tool)

    def to_inputs(self) -> dict:
        """The JSON ``inputs`` object (keys of format version 1, plus the newer ones and
        the operation's kind, so that a saved program reads back as what it was)."""
        common = dict(radius=self.tool.radius, allowance=self.tool.allowance,
                      feed=self.feed, period=self.period, offsets=list(self.offsets),
                      source=self.source, shank_length=self.tool.shank_length,
                      clearance=self.clearance, flip_material=self.flip_material,
                      plunge_feed=self.plunge_feed, spindle=self.spindle,
                      axis=list(self.axis),
                      origin=None if self.origin is None else list(self.origin))
        return {**common, **self.operation.to_inputs()}

    @classmethod
    def from_inputs(cls, inputs: dict, faces=(None, None)) -> "Job":
        """The job recorded in a toolpath JSON's ``inputs`` (InputError if malformed)."""
        if not isinstance(inputs, dict):
            raise InputError(f"the recorded job must be an object, got "
                             f"{type(inputs).__name__}")
        try:
            tool = Tool(inputs["radius"], inputs.get("allowance", 0.0),
                        inputs.get("shank_length"))
            kind = inputs.get("operation", "path")
            if kind == "finish":
                op = finishing(inputs.get("strategy", "raster"), inputs["faces"],
                               **{k: inputs.get(k, default)
                                  for k, default in FINISH_FIELDS.items()})
            elif kind == "pencil":
                op = Pencil(inputs.get("faces"), inputs.get("side", "climb"))
            elif kind == "path":
                # offsets are recorded resolved: R' itself means "the tool's offset"
                offsets = tuple(None if o == tool.offset else o
                                for o in (inputs.get("offsets") or (None, None)))
                op = PairPath(faces=tuple(inputs.get("faces") or faces), offsets=offsets,
                              start=inputs.get("start"), end=inputs.get("end"),
                              edge=inputs.get("edge", 0), stretch=inputs.get("stretch"))
            else:
                raise InputError(f"the recorded job's operation {shown(kind)} is not one of "
                                 "path, pencil, finish")
            return cls(tool, inputs["feed"], inputs["period"], op, inputs.get("source"),
                       inputs.get("clearance"),
                       flip_material=bool(inputs.get("flip_material", False)),
                       plunge_feed=inputs.get("plunge_feed"), spindle=inputs.get("spindle"),
                       axis=inputs.get("axis", PRINCIPAL_AXES["+Z"]),
                       origin=inputs.get("origin"))
        except KeyError as e:
            raise InputError(f"the recorded job has no {e.args[0]!r}") from None
        except TypeError as e:
            raise InputError(f"the recorded job is malformed: {e}") from None
