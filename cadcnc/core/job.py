"""What the user asked for: one typed, validated record per machining job.

A :class:`Job` holds what every operation shares (the part's source, the tool, feed,
plunge feed, spindle speed, period, clearance height, tolerances) and one operation record
(:class:`PairPath`, the path along the intersection of two faces; :class:`Pencil`, every
inner corner of a part; :class:`Finish`, raster finishing of faces). It is
validated once, where it is built; everything downstream (the API, the toolpath, the
APT-like programs, the CLI, the JSON writer and reader) reads its fields, never string
keys. Units: lengths mm, feed mm/min, period s.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

from .errors import InputError
from .finish_fields import check_strategy
from .tolerances import DEFAULT, Tolerances
from .units import PRINCIPAL_AXES, axis_name, check_axis  # noqa: F401 - the Job's axis
from .units import Point, check_faces, check_number, check_point, shown  # noqa: F401 - checks of every record

SHANK_LENGTH_RADII = 10.0  # default shank length, in ball radii
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
class Tool:
    """A ball-end cutter: ball radius R on a cylindrical shank of radius R along +Z.

    ``radius`` R and ``allowance`` C (stock left on the faces) in mm; the ball's offset from
    the faces is R' = R + C. ``shank_length`` (mm) above the ball centre, default 10 R.
    """

    radius: float
    allowance: float = 0.0
    shank_length: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "radius", check_number("radius", self.radius, "mm",
                                                        allow_zero=True))
        object.__setattr__(self, "allowance", check_number("allowance", self.allowance,
                                                           "mm", allow_zero=True))
        if self.shank_length is not None:
            object.__setattr__(self, "shank_length", check_number(
                "shank length", self.shank_length, "mm", allow_zero=True))

    @property
    def offset(self) -> float:
        """R' = R + C, mm: the ball centre's distance from a face it touches."""
        return self.radius + self.allowance

    @property
    def shank(self) -> float:
        """Shank length above the ball centre, mm (default 10 R)."""
        return SHANK_LENGTH_RADII * self.radius if self.shank_length is None \
            else self.shank_length


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

    def to_inputs(self) -> dict:
        return dict(operation="pencil",
                    faces=None if self.faces is None else list(self.faces), side=self.side)


FINISH_PATTERNS = ("zigzag", "oneway")


@dataclass(frozen=True)
class Finish:
    """The ``finish`` operation: raster passes of the ball over the selected ``faces``
    (1-based numbers), its centre on vertical guide planes at ``angle`` degrees to +X.

    Exactly one of ``stepover`` (mm, the planes' fixed spacing) and ``scallop`` (mm, the
    largest scallop height the adaptive spacing allows) is given; ``pattern`` "zigzag"
    (every other pass reversed, staying down where the move is verified clear) or
    "oneway" (every pass the same way, retracting between passes).
    """

    faces: tuple[int, ...]
    stepover: float | None = None
    scallop: float | None = None
    angle: float = 0.0
    pattern: str = "zigzag"
    stepdown: float | None = None   # mm, waterline levels' spacing (check_strategy)
    strategy: str = "raster"
    threshold: float = 45.0         # deg
    side: str = "climb"
    overlap: float = 0.0            # mm

    def __post_init__(self):
        if isinstance(self.faces, (tuple, list)) and not self.faces:
            raise InputError("finishing needs at least one face")
        object.__setattr__(self, "faces", check_faces(self.faces))
        check_strategy(self)
        if self.strategy == "raster" and (self.stepover is None) == (self.scallop is None):
            raise InputError("give exactly one of stepover (the planes' spacing, mm) and "
                             "scallop (the largest scallop height, mm)"
                             + ("" if self.stepover is None else
                                f", got stepover {shown(self.stepover)} and scallop "
                                f"{shown(self.scallop)}"))
        if self.stepover is not None:
            object.__setattr__(self, "stepover", check_number("stepover", self.stepover,
                                                              "mm"))
        if self.scallop is not None:
            object.__setattr__(self, "scallop", check_number("scallop", self.scallop, "mm"))
        a = self.angle
        if isinstance(a, bool) or not isinstance(a, numbers.Real) or not math.isfinite(a):
            raise InputError(f"angle must be a finite number of degrees, got {shown(a)}")
        object.__setattr__(self, "angle", float(a))
        if self.pattern not in FINISH_PATTERNS:
            raise InputError(f"pattern must be one of {', '.join(FINISH_PATTERNS)}, got "
                             f"{shown(self.pattern)}")

    def resolved_offsets(self, tool: Tool) -> tuple[float, float]:
        """(R', 0): the faces at the tool's offset, the guide plane carrying the centre."""
        return (tool.offset, 0.0)

    def to_inputs(self) -> dict:
        return dict(operation="finish", faces=list(self.faces), stepover=self.stepover,
                    scallop=self.scallop, angle=self.angle, pattern=self.pattern,
                    stepdown=self.stepdown, strategy=self.strategy,
                    threshold=self.threshold, side=self.side, overlap=self.overlap)


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
    operation: PairPath | Pencil | Finish = field(default_factory=PairPath)
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
        for name, kinds in (("tool", (Tool,)), ("operation", (PairPath, Pencil, Finish)),
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
                op = Finish(inputs["faces"], inputs.get("stepover"), inputs.get("scallop"),
                            inputs.get("angle", 0.0), inputs.get("pattern", "zigzag"),
                            inputs.get("stepdown"), inputs.get("strategy", "raster"),
                            inputs.get("threshold", 45.0), inputs.get("side", "climb"),
                            inputs.get("overlap", 0.0))
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
