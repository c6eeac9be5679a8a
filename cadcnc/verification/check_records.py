"""One typed record per check, with its JSON form (``to_dict``).

Callers read attributes, never guessed keys. Lengths in mm; cycle ranges are [first,
last] pairs of cycle numbers, inclusive; trim states are :mod:`cadcnc.core.trim_labels`'s strings.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields

import numpy as np


@dataclass
class SurfaceCheck:
    """One face of the pair: deviations per cycle (N,) and their summary, mm.

    ``deviation``: against the untrimmed surface; ``face_deviation``: against the trimmed
    face (its nearest point, boundary included); ``states`` the foot point's trim state
    per cycle (:mod:`cadcnc.core.trim_labels`). ``max_trim_gap_mm``: the largest trimmed minus
    untrimmed distance (> 0 where the nearest surface point lies outside the face: the
    ball touches only the surface's extension there); ``off_face_cycles`` the cycle ranges
    where it exceeds ``Tolerances.off_face``. ``unseeded_*``: the global re-projection check.
    """

    face: int | None
    offset: float
    deviation: np.ndarray = field(repr=False)
    face_deviation: np.ndarray = field(repr=False)
    states: list[str] = field(repr=False)
    max_overcut_mm: float = 0.0
    overcut_cycle: int = -1
    max_undercut_mm: float = 0.0
    undercut_cycle: int = -1
    surface_max_overcut_mm: float = 0.0
    percentiles_mm: dict[str, float] = field(default_factory=dict)
    max_trim_gap_mm: float = 0.0
    off_face_cycles: list[list[int]] = field(default_factory=list)
    unseeded_checked: int = 0
    unseeded_disagreements: int = 0
    unseeded_max_gain_mm: float = 0.0

    def to_dict(self) -> dict:
        """The summary without the per-cycle arrays."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if f.name not in ("deviation", "face_deviation", "states")}


@dataclass
class ReferenceCheck:
    """The path against OCCT's intersection curve (its branch), all lengths mm.

    ``points_to_branch`` (N,): exact distance of each cutter centre to the branch.
    ``path_to_branch_mm``: max of that and of the path's segment midpoints (chord sag
    included); ``branch_to_path_mm``: max distance of the branch, within the path's span,
    to the path polyline; ``hausdorff_mm`` the larger of the two. ``coverage`` in [0, 1],
    the *curve coverage*: the fraction of the branch over the path's own span (its start
    to its last point, or the whole loop; ``own_span_mm`` long) lying within
    ``cover_radius_mm`` of a cutter centre, so a path that ends early is judged on what it
    covers. ``intended_coverage``: the same over ``span_mm``, from the start to the
    intended end; ``gaps`` its uncovered stretches (from, to) in mm of arc length from the
    start. ``residual_mm``: how far OCCT's own curve is from the offset surfaces (the
    reference's accuracy).
    """

    n_curves: int = 0
    branch_curves: list[int] = field(default_factory=list)
    occt_seconds: float = math.nan
    points_to_branch: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    points_max_mm: float = math.nan
    points_worst_cycle: int = -1
    path_to_branch_mm: float = math.nan
    branch_to_path_mm: float = math.nan
    hausdorff_mm: float = math.nan
    coverage: float = math.nan
    cover_radius_mm: float = math.nan
    span_mm: float = math.nan
    gaps: list[tuple[float, float]] = field(default_factory=list)
    residual_mm: float = math.nan
    note: str = ""
    intended_coverage: float = math.nan
    own_span_mm: float = math.nan

    def to_dict(self) -> dict:
        """The summary without the per-cycle distances."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if f.name != "points_to_branch"}


@dataclass
class FeedCheck:
    """Measured step lengths |p_k - p_(k-1)| against the commanded f_k.

    ``max_rel_error`` |measured - commanded| / commanded, worst at ``worst_cycle`` (-1 when
    the path has no step); ``excluded_last``: a shortened last step (end landing) was left
    out. ``recorded_vs_measured_mm``: the toolpath's own step lengths against the points.
    Feeds in mm/min; nan where the path has no step.
    """

    max_rel_error: float = 0.0
    worst_cycle: int = -1
    worst_step_mm: float = math.nan
    worst_commanded_mm: float = math.nan
    excluded_last: bool = False
    last_step_mm: float = math.nan
    recorded_vs_measured_mm: float = math.nan
    commanded_min_mm: float = math.nan
    commanded_max_mm: float = math.nan
    feed_profile: bool = False
    feed_min_mm_min: float = math.nan
    feed_max_mm_min: float = math.nan

    def to_dict(self) -> dict:
        return asdict(self)


BOUND_NAMES = ("eq11", "eq12", "eq16")


@dataclass
class TheoryRow:
    """One face: the measured deviation at point k+1 against the bounds of the step from k.

    ``eqNN_max_mm``: the largest bound; ``eqNN_exceeded_overcut`` / ``_abs``: cycles whose
    over-cut / absolute deviation is above the bound by more than ``Tolerances.noise``.
    ``worst_ratio_to_eq16`` |deviation| / eq. 16 bound at its worst cycle. The bound
    fields are None when the toolpath carries no bounds (``has_bounds`` False).
    """

    face: int | None
    measured_overcut_mm: float
    measured_abs_mm: float
    eq11_max_mm: float | None = None
    eq11_exceeded_overcut: int | None = None
    eq11_exceeded_abs: int | None = None
    eq12_max_mm: float | None = None
    eq12_exceeded_overcut: int | None = None
    eq12_exceeded_abs: int | None = None
    eq16_max_mm: float | None = None
    eq16_exceeded_overcut: int | None = None
    eq16_exceeded_abs: int | None = None
    worst_ratio_to_eq16: float | None = None
    worst_ratio_cycle: int | None = None

    @property
    def has_bounds(self) -> bool:
        return self.eq16_max_mm is not None

    def to_dict(self) -> dict:
        """The row; without bounds, only the face and the measured values."""
        d = asdict(self)
        if not self.has_bounds:
            d = {k: d[k] for k in ("face", "measured_overcut_mm", "measured_abs_mm")}
        return d


@dataclass
class StopCheck:
    """Where the last contacts lie, and whether that matches the stop reason.

    ``last_contact_states``: per face, the last foot point's trim state
    (:mod:`cadcnc.core.trim_labels`) with the loose classifier ``Tolerances.classify_loose``; ``span``
    what the path was meant to cover ("closed", "end" or "target"); ``remaining_mm`` the
    uncovered reference length at the end of that span; ``consistent`` None when the stop
    reason says nothing checkable; ``left_face`` the faces whose last foot is not inside.
    """

    reason: str
    last_contact_states: list[str]
    span: str
    remaining_mm: float
    consistent: bool | None
    left_face: list[int | None]

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass
class WholePartHit:
    """One face of the part that the ball cuts deeper than ``Tolerances.hit``.

    ``followed``: the face is one of the pair. ``depth_mm``: the deepest cut, at
    ``worst_cycle`` (nan when a distance to the face could not be measured: such cycles
    count as hits, ``worst_cycle`` then names the first of them); ``n_cycles`` cycles in
    the ranges ``cycles``.
    """

    face: int
    followed: bool
    depth_mm: float
    worst_cycle: int
    n_cycles: int
    cycles: list[list[int]]

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass
class WholePartCheck:
    """The ball of radius ``ball_radius_mm`` at every centre against every face of the part.

    ``faces_checked``: faces of the part (those whose boxes came within reach of the path
    were measured: ``faces_near``). ``max_depth_mm``: the deepest cut into any face at any
    centre (0 when the ball cuts nothing; nan when a depth could not be measured).
    ``material``: how membership was decided ("solid": OCCT's solid classifier, "faces":
    the nearest face's side, for a part without a solid); ``classified``: classifier calls.
    """

    hits: list[WholePartHit] = field(default_factory=list)
    faces_checked: int = 0
    distances_evaluated: int = 0
    ball_radius_mm: float = math.nan
    hit_tolerance_mm: float = math.nan
    max_depth_mm: float = 0.0
    faces_near: int = 0
    material: str = ""
    classified: int = 0

    def to_dict(self) -> dict:
        """The summary, without the hits (``whole_part_hits`` at the top level)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "hits"}


@dataclass
class SweepHit:
    """One face the swept ball cuts deeper than the allowance along some moves.

    Move k is the straight line from position k to k + 1 of the polyline checked.
    ``depth_mm``: the deepest cut found on those moves, at ``worst_move`` (exact where
    ``exact``, else measured at a sampled point: then the true depth is at least this);
    ``n_moves`` moves in the ranges ``moves``; nan when a distance was not measurable.
    """

    face: int
    depth_mm: float
    worst_move: int
    n_moves: int
    moves: list[list[int]]
    exact: bool = False

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass
class SweepCheck:
    """The ball swept along every straight move of a polyline, against every face.

    ``proven``: every move is proven to cut no deeper than ``allowance_mm`` (the gouge
    limit less ``blend_mm``), i.e. to stay at least ``clearance_mm`` = R' - allowance
    from the part, outside it. ``depth_bound_mm``: the proven upper bound of the depth
    over all moves (docs/notes/gate.md); ``depth_mm``: the deepest depth measured (a lower
    bound of the true deepest; exact on moves that needed the exact step).
    ``hits``: the faces cut beyond the allowance. ``distances_evaluated``: point-to-face
    distances; ``exact_moves``: segment-to-face distances (the exact step).
    """

    n_moves: int = 0
    proven: bool = True
    allowance_mm: float = math.nan
    blend_mm: float = 0.0
    clearance_mm: float = math.nan
    depth_bound_mm: float = -math.inf
    depth_mm: float = -math.inf
    worst_move: int = -1
    hits: list[SweepHit] = field(default_factory=list)
    faces_near: int = 0
    distances_evaluated: int = 0
    exact_moves: int = 0
    classified: int = 0

    def to_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "hits"}
        d["hits"] = [h.to_dict() for h in self.hits]
        return d


@dataclass(frozen=True)
class Criterion:
    """One line of the verdict: ``name`` measured ``value`` against ``limit`` (mm, or a
    fraction for coverage); ``ok`` False when it fails or could not be measured."""

    name: str
    value: float
    limit: float
    ok: bool
    detail: str = ""

    def to_dict(self) -> dict:
        return asdict(self)


def strict_max(values) -> float:
    """The largest value; nan when any value is nan (Python's max may drop a nan)."""
    values = [float(v) for v in values]
    return math.nan if any(math.isnan(v) for v in values) else max(values)


def deepest(overcut_mm: float, hits: list[WholePartHit]) -> float:
    """The deepest cut into any face, mm; nan when any depth is unmeasured (nan)."""
    return strict_max([overcut_mm, *(h.depth_mm for h in hits)])


def cycle_ranges(cycles) -> list[list[int]]:
    """[first, last] runs of consecutive cycle numbers."""
    out: list[list[int]] = []
    for c in map(int, cycles):
        if out and c == out[-1][1] + 1:
            out[-1][1] = c
        else:
            out.append([c, c])
    return out
