"""A program of linked moves: cut segments (toolpaths), link segments and what was skipped.

Every operation returns a :class:`Program` (a two-face path is a program of one cut), and
writers, verification and plots read only this type. Points are ball centres in mm; a
program is machined in the order of ``segments``.

- :class:`CutSegment`: one :class:`~cadcnc.program.toolpath.Toolpath` (a stretch of a
  corner, a pass), with the shared edge and stretch it follows when known.
- :class:`LinkSegment`: the moves between two cuts, (M, 3) points; move k (from point k
  to k + 1) is a rapid where ``rapid[k]``, else a feed move at the plunge feed.
- :class:`Skipped`: a corner, stretch or pass that was found and not cut, with its reason.

A program is complete when every cut is complete (stopped where it was meant to, an
intended end or the limit of a stretch) and nothing is listed as stopped short; what was
found and could not be cut is listed in ``skipped``. ``notes`` are sentences for the user
(a start moved into a stretch).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.job import Job
from .summary import program_summary
from .toolpath import Toolpath


@dataclass
class CutSegment:
    """One cut: the toolpath, and the shared edge / stretch it follows (1-based, or None).

    ``at_limit``: the cut stopped at the limit of its stretch (a contact reaching its
    face's boundary, a third face or the shank touching): an intended end, like the end
    point itself.
    """

    path: Toolpath
    edge: int | None = None
    stretch: int | None = None
    at_limit: bool = False

    kind = "cut"

    @property
    def points(self) -> np.ndarray:
        """(N, 3) ball centres, mm."""
        return self.path.points

    @property
    def length(self) -> float:
        return self.path.length

    @property
    def complete(self) -> bool:
        """Stopped where it was meant to: its end, once around, or its stretch's limit."""
        return self.path.complete or self.at_limit


@dataclass
class LinkSegment:
    """Moves between cuts: (M, 3) ball centres; ``rapid`` (M - 1,) bool per move (False:
    a feed move at the plunge feed)."""

    points: np.ndarray
    rapid: np.ndarray

    kind = "link"

    def __post_init__(self):
        self.points = np.asarray(self.points, dtype=float).reshape(-1, 3)
        self.rapid = np.asarray(self.rapid, dtype=bool).reshape(-1)
        if len(self.points) < 2 or len(self.rapid) != len(self.points) - 1:
            raise ValueError(f"a link needs M >= 2 points and M - 1 move flags, got "
                             f"{len(self.points)} points and {len(self.rapid)} flags")

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    @property
    def feed_length(self) -> float:
        """Length of the moves made at the plunge feed (not rapid), mm."""
        d = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        return float(d[~self.rapid].sum())


STOPPED_SHORT = "stopped short"
"""Skipped reason of the rest of a stretch after a cut that stopped before its end."""
FAILED = "failed"
"""Skipped reason of what could not be computed (or failed its self-check): not complete."""


@dataclass(frozen=True)
class Skipped:
    """A corner, stretch or pass found and not cut: the faces, the shared edge (1-based,
    or None), a short ``reason`` key and a sentence for the user."""

    faces: tuple[int | None, int | None]
    reason: str
    detail: str = ""
    edge: int | None = None


def _edge_of(path: Toolpath) -> int | None:
    """The 1-based shared edge a two-face path follows (None when it ran from a start)."""
    op = path.job.operation
    return op.edge + 1 if getattr(op, "start", None) is None and hasattr(op, "edge") else None


@dataclass
class Program:
    """Cut and link segments in machining order, the job, and what was skipped."""

    job: Job
    segments: list = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @classmethod
    def of_paths(cls, paths: list[Toolpath], job: Job | None = None,
                 skipped: list[Skipped] | None = None) -> "Program":
        """Cuts in the given order, without links (writers approach each cut from above)."""
        paths = list(paths)
        if job is None:
            if not paths:
                raise ValueError("a program of no path needs its job")
            job = paths[0].job
        return cls(job, [CutSegment(p, edge=_edge_of(p)) for p in paths],
                   list(skipped or []))

    # -- views ---------------------------------------------------------------------------
    @property
    def cuts(self) -> list[CutSegment]:
        return [s for s in self.segments if s.kind == "cut"]

    @property
    def links(self) -> list[LinkSegment]:
        return [s for s in self.segments if s.kind == "link"]

    @property
    def paths(self) -> list[Toolpath]:
        """The toolpaths of the cuts, in order."""
        return [s.path for s in self.cuts]

    @property
    def cut_length(self) -> float:
        return float(sum(s.length for s in self.cuts))

    @property
    def link_length(self) -> float:
        return float(sum(s.length for s in self.links))

    @property
    def time_at_feed(self) -> float:
        """Seconds at feed: the cuts' cycles, plus the links' feed moves at the job's feed."""
        cut = sum(s.path.duration for s in self.cuts)
        plunge = sum(s.feed_length for s in self.links) / self.job.feed * 60.0
        return float(cut + plunge)

    @property
    def complete(self) -> bool:
        """Every cut stopped where it was meant to (nothing partial passed as whole)."""
        return all(s.complete for s in self.cuts) and not any(
            s.reason in (STOPPED_SHORT, FAILED) for s in self.skipped)

    @property
    def partial_reasons(self) -> list[str]:
        """One sentence per cut that stopped short of its intended end."""
        return [f"cut {k}: {s.path.partial_reason}" for k, s in enumerate(self.cuts, 1)
                if not s.complete]

    def all_moves(self) -> np.ndarray:
        """(M, 3) every ball-centre position commanded, in order (cuts and links)."""
        parts = [s.points for s in self.segments]
        return np.vstack(parts) if parts else np.zeros((0, 3))

    def totals(self) -> dict:
        """Cut and link length (mm), time at feed (s), counts of cuts and skipped."""
        return {"cut_length_mm": self.cut_length, "link_length_mm": self.link_length,
                "time_at_feed_s": self.time_at_feed, "cuts": len(self.cuts),
                "links": len(self.links), "skipped": len(self.skipped)}

    def summary(self, part_name: str = "") -> str:
        """The text summary (:func:`~cadcnc.program.summary.program_summary`)."""
        return program_summary(self, part_name)

    def __repr__(self) -> str:
        return (f"<Program {len(self.cuts)} cuts, {len(self.links)} links, "
                f"{self.cut_length:.3f} mm cut, {len(self.skipped)} skipped>")
