"""The verification report: every check's record, and the JSON of ``cadcnc verify --json``.

:meth:`VerificationReport.to_dict` writes the documented JSON (its keys are those of
format 1: tests/verification/test_verification.py pins them). Sign convention: a deviation is the
cutter centre's signed distance from a surface (+ out of the material) minus the
surface's offset R', so a negative deviation is an over-cut (a gouge). Lengths in mm,
times in s.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..core.jsonable import plain
from ..core.tolerances import DEFAULT, Tolerances
from .check_records import (
    Criterion,
    FeedCheck,
    ReferenceCheck,
    StopCheck,
    SurfaceCheck,
    SweepCheck,
    TheoryRow,
    WholePartCheck,
    WholePartHit,
    strict_max,
)
from .table import format_table
from .verdict import criteria


@dataclass
class VerificationReport:
    """Everything :func:`~cadcnc.verification.verify` measured.

    ``to_dict()`` for JSON, ``format_table()`` for people. ``radius`` R and
    ``ball_radius`` R' = R + C (mm); ``tolerances`` the record the checks used (the
    limits of the verdict: ``gouge``, ``accuracy``, ``hausdorff``, ``coverage``).
    ``sweep``: the ball swept along the path's moves (None when the whole-part check
    was skipped).
    """

    faces: tuple
    n_points: int
    radius: float
    ball_radius: float
    offsets: tuple
    stop_reason: str
    stop_detail: str
    surfaces: list[SurfaceCheck]
    reference: ReferenceCheck
    feed: FeedCheck
    theory: list[TheoryRow]
    whole_part: WholePartCheck
    stop: StopCheck
    edge_deviation_mm: float | None = None
    seconds: dict[str, float] = field(default_factory=dict)
    tolerances: Tolerances = field(default=DEFAULT, repr=False)
    sweep: SweepCheck | None = None

    @property
    def max_overcut_mm(self) -> float:
        return strict_max(s.max_overcut_mm for s in self.surfaces)

    @property
    def max_undercut_mm(self) -> float:
        return strict_max(s.max_undercut_mm for s in self.surfaces)

    @property
    def hausdorff_mm(self) -> float:
        return self.reference.hausdorff_mm

    @property
    def coverage(self) -> float:
        return self.reference.coverage

    @property
    def whole_part_hits(self) -> list[WholePartHit]:
        return self.whole_part.hits

    @property
    def max_gouge_mm(self) -> float:
        """Deepest cut of the ball into any face of the part (the pair's included), at the
        centres and along the moves where they were examined, mm (material-aware; the
        pair's over-cut when the whole-part check was skipped)."""
        if self.sweep is None:
            return strict_max([self.max_overcut_mm,
                               *(h.depth_mm for h in self.whole_part_hits)])
        return strict_max([self.whole_part.max_depth_mm, self.sweep.depth_mm])

    def criteria(self, tolerance_mm: float | None = None) -> list[Criterion]:
        """Every criterion (gouge, deviation, hausdorff, coverage) with its pass or fail;
        ``tolerance_mm`` overrides the gouge limit (see :mod:`.verdict`)."""
        return criteria(self, tolerance_mm)

    @property
    def verdict(self) -> list[Criterion]:
        """The criteria that fail at the report's own tolerances (empty when all pass)."""
        return [c for c in self.criteria() if not c.ok]

    def ok(self, tolerance_mm: float | None = None) -> bool:
        """True when every criterion passes: no face gouged deeper than ``tolerance_mm``
        (default the gouge limit of :attr:`tolerances`) at the centres or along the
        moves, deviation, Hausdorff and coverage within their tolerances. False when
        anything could not be measured."""
        return all(c.ok for c in self.criteria(tolerance_mm))

    def to_dict(self) -> dict:
        """JSON-ready summary (no per-cycle arrays; non-finite numbers become None)."""
        return plain(dict(
            max_overcut_mm=self.max_overcut_mm, max_undercut_mm=self.max_undercut_mm,
            hausdorff_mm=self.hausdorff_mm, coverage=self.coverage,
            whole_part_hits=[h.to_dict() for h in self.whole_part_hits],
            max_gouge_mm=self.max_gouge_mm, faces=list(self.faces), n_points=self.n_points,
            radius=self.radius, ball_radius=self.ball_radius, offsets=list(self.offsets),
            stop_reason=self.stop_reason, stop_detail=self.stop_detail,
            stop=self.stop.to_dict(), surfaces=[s.to_dict() for s in self.surfaces],
            reference=self.reference.to_dict(), feed=self.feed.to_dict(),
            theory=[t.to_dict() for t in self.theory], whole_part=self.whole_part.to_dict(),
            edge_deviation_mm=self.edge_deviation_mm, seconds=self.seconds,
            sweep=None if self.sweep is None else self.sweep.to_dict(), ok=self.ok(),
            criteria=[c.to_dict() for c in self.criteria()]))

    def format_table(self, tolerance_mm: float | None = None) -> str:
        """A text table, each criterion's pass or fail last (``tolerance_mm`` overrides
        the gouge limit)."""
        return format_table(self, self.tolerances.gouge if tolerance_mm is None
                            else tolerance_mm)
