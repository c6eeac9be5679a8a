"""The verdict on one ball position of a pair of faces: feasible, or the first rule it fails.

A *feasible* ball position of a pair (i, j) is a centre touching both offset surfaces
(Newton, :func:`~cadcnc.interp.tangency.solve_tangency`) whose feet lie on the trimmed
faces (inside or on the boundary), where the faces are not tangent (|n1 x n2| at least
``Tolerances.stretch_tangent_sin``), where neither contact's concave curvature along the
path is tighter than the ball (R' k <= 1, up to the spec's 1 um), and where the ball and
its shank clear the rest of the part (:class:`~cadcnc.guard.clearance.ClearanceGuard`).
:class:`Feasibility` judges a position and records each rule's signed margin (> 0 on the
feasible side) for the root search of a stretch's limits (:mod:`.limit_search`); the
stretches themselves are :mod:`.stretches`'. Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ...core.errors import GeometryError, StartPointError
from ...core.job import Job
from ...core.tolerances import Tolerances
from ...guard.clearance import ClearanceGuard
from ...interp.cycle import Contact
from ...interp.stepper import Tangency
from ...interp.tangency import solve_tangency

FEASIBLE = "feasible"
BOUNDARY, COLLISION, CURVATURE, TANGENT = "boundary", "collision", "curvature", "tangent"
UNSOLVED = "unsolved"   # no tangency found from the sample's anchor

ONE_SIDED = (COLLISION,)
"""Rules whose margin is exact only where they fail (the guard's clearance: a lower bound
where it clears, :mod:`.limit_search`)."""

REASONS = {
    BOUNDARY: "a contact lies off its face",
    COLLISION: "a third face (or the shank) is in the way",
    CURVATURE: "concave curvature tighter than the ball",
    TANGENT: "the faces are tangent",
    UNSOLVED: "no ball position touches both faces",
}


@dataclass(frozen=True)
class Sample:
    """One ball position tried at arc length ``s`` (mm) along the edge, and its verdict."""

    s: float
    rule: str                       # FEASIBLE or the first rule that fails
    detail: str
    tangency: Tangency | None       # None when no tangency was found
    tangent: tuple[float, float, float]   # the edge's unit tangent at the anchor
    margins: dict = field(default_factory=dict, compare=False)
    """The signed margins the verdict computed, by rule (> 0 feasible side; see
    :mod:`.limit_search`): every rule's with a margin on a feasible sample, up to the
    failing one on another."""

    @property
    def ok(self) -> bool:
        return self.rule == FEASIBLE


class Feasibility:
    """The verdict on a ball position of a pair: tangency, trims, curvature, clearance."""

    def __init__(self, s1, s2, job: Job, guard: ClearanceGuard | None):
        self.s1, self.s2, self.job = s1, s2, job
        self.offsets = job.offsets
        self.tol = job.tolerances
        self.guard = guard
        self.max_reach = 10.0 * max(max(self.offsets), 1e-3)   # mm from the anchor
        self.samples, self.beat = 0, None   # positions judged; called after each (progress)

    def sample(self, s: float, anchor, tangent, seed: Tangency | None = None,
               quick: bool = False) -> Sample:
        """Solve the tangency in the plane through ``anchor`` normal to ``tangent`` (seeded
        from ``seed`` or the projections of the anchor) and judge it; ``quick``: a hit the
        guard proves from a nearby one (:meth:`ClearanceGuard.proven_hit`), or the first
        face found cutting in (:meth:`ClearanceGuard.first_hit`), is taken without the
        exact clearance (the sample then has no COLLISION margin; :meth:`exact`)."""
        tangent = tuple(map(float, tangent))
        self.samples += 1
        if self.beat is not None:
            self.beat()
        try:
            seeds = ([seed.uv1, seed.uv2] if seed is not None else
                     [_project(s, anchor) for s in (self.s1, self.s2)])
            tan = solve_tangency(self.s1, self.s2, self.offsets, *seeds, anchor,
                                 direction=tangent, tol=self.tol, what="sample")
        except (StartPointError, GeometryError, ArithmeticError) as exc:
            return Sample(s, UNSOLVED, str(exc), None, tangent)
        if np.linalg.norm(np.subtract(tan.p, anchor)) > self.max_reach:
            return Sample(s, UNSOLVED, "the tangency found is far from the edge", None,
                          tangent)
        margins: dict[str, float] = {}
        rule, detail = self._verdict(tan, margins, quick)
        return Sample(s, rule, detail, tan, tangent, margins)

    def exact(self, x: Sample) -> Sample:
        """``x`` judged again with every margin it failed on exact (a quick sample)."""
        if x.tangency is None or x.rule != COLLISION or COLLISION in x.margins:
            return x
        margins: dict[str, float] = {}
        rule, detail = self._verdict(x.tangency, margins)
        return replace(x, rule=rule, detail=detail, margins=margins)

    def judge(self, tan: Tangency) -> tuple[str, str]:
        """(FEASIBLE, "") or the first failing rule and a detail naming the face."""
        return self._verdict(tan, {})

    def _verdict(self, tan: Tangency, margins: dict, quick: bool = False) -> tuple[str, str]:
        """:meth:`judge`, filling ``margins`` with each rule's signed margin as it is
        checked (from what the check computes: no call is added); ``quick``: see
        :meth:`sample`."""
        c1 = Contact(self.s1, self.offsets[0], *tan.uv1)
        c2 = Contact(self.s2, self.offsets[1], *tan.uv2)
        t = np.cross(c1.n, c2.n)
        sin = float(np.linalg.norm(t))
        margins[TANGENT] = sin - self.tol.stretch_tangent_sin
        if sin < self.tol.stretch_tangent_sin:
            return TANGENT, f"|n1 x n2| = {sin:.3g}"
        off = [f"face {s.number}" for s, uv in ((self.s1, tan.uv1), (self.s2, tan.uv2))
               if not s.contains(*uv)]
        if off:
            return BOUNDARY, "contact off " + " and ".join(off)
        t = tuple(t / sin)
        margins[CURVATURE] = math.inf
        for c, s in ((c1, self.s1), (c2, self.s2)):
            k = c.curvature(t)
            if c.offset > 0.0:
                margins[CURVATURE] = min(margins[CURVATURE], 1.0 + self.tol.gouge / (
                    2.0 * c.offset) - c.offset * k)
            if too_tight(c.offset * k, c.offset, self.tol):
                return CURVATURE, f"face {s.number}: R' k = {c.offset * k:.4g} > 1"
        if self.guard is not None:
            hit = self.guard.proven_hit(tan.p) if quick else None
            if hit is not None:
                return COLLISION, f"{hit[1]} (at least {-hit[0]:.4g} mm too near)"
            m, detail, exact = self.guard.first_hit(tan.p) if quick else \
                (*self.guard.margin(tan.p), True)
            if not exact:
                return COLLISION, f"{detail} (at least {-m:.4g} mm too near)"
            margins[COLLISION] = m
            if m < 0.0:
                return COLLISION, f"{detail} ({-m:.4g} mm too near)"
        return FEASIBLE, ""


def too_tight(rk: float, offset: float, tol: Tolerances) -> bool:
    """Whether a concave curvature k with R' k = ``rk`` is tighter than a ball of offset
    R' (mm) can follow. R' k = 1 is a tie (a hole of the ball's radius is not cut); past
    1 + gouge / 2 R' it cuts deeper than the spec's 1 um (a cylinder of radius R'/(R' k)
    is cut by ~2 R' (R' k - 1)). A ball of R' <= 0 is a point: nothing is too tight."""
    if not offset > 0.0:
        return False
    return rk > 1.0 + tol.gouge / (2.0 * offset)


def _project(surface, point) -> tuple[float, float]:
    """(u, w) nearest ``point``: in the face's box, else on the whole surface."""
    try:
        return surface.project(point)[:2]
    except GeometryError:
        return surface.project(point, within_face_box=False)[:2]
