"""Entries through free space: how the tool gets to a cut and away from it, one rule for
``path``, ``pencil`` and ``finish``.

A cut (a stretch of a corner, a finishing pass) is entered wherever the tool can get
there, then cut along its whole length. :func:`visit_for` tries, in this order:

1. a straight plunge from the clearance height onto its start (cut as computed);
2. the same onto its end (the cut run the other way);
3. a plunge onto a point between (one every R' along the cut, INTERIOR to MAX_INTERIOR
   points, tried from the start on), cutting
   both ways from there: to the end, back along the cut to that point, then to the start;
4. a straight horizontal approach at the cut's own height from outside the part's
   bounding box, along +X, -X, +Y or -Y (SIDES), onto its start, its end, or a point
   between (SIDE_POINTS of them).

The tool leaves straight up from the last point cut when that plunge is clear, else it
goes back along the cut (points already cut) to where it came in and leaves that way.
A plunge is clear when the ball and a shank from it up past the clearance height keep
R' - gouge limit from every face (the stepper's guard with a longer shank,
:func:`~cadcnc.guard.guard_for`), so the ball's and shank's sweep down to it is clear; a
horizontal approach when the ball and shank (its length as for the cuts) swept along it,
and down outside the part to its height, keep the same distance
(:class:`~cadcnc.guard.moves.MoveClearance`, OCCT's distance). A cut with no clear
entry is skipped as UNREACHABLE, naming its start and the face in the way. Lengths mm.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..core.job import Job
from ..guard import FINISH_OWN_SHARE, PAIR_OWN_SHARE, MoveClearance, guard_for
from ..interp.cycle import END
from ..parallel.pool import check_jobs
from ..parallel.tasks import on_workers
from ..program.linking import Visit, linked
from ..program.program import CutSegment, LinkSegment, Skipped
from ..program.toolpath import toolpath_piece

UNREACHABLE = "unreachable"
SIDES = ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, -1.0, 0.0))
"""Horizontal unit directions (in the setup's frame) from a cut out to where a side
approach starts: the tool comes in from the +X, -X, +Y, -Y side of the part."""
SIDE_NAMES = ("+X", "-X", "+Y", "-Y")
INTERIOR, MAX_INTERIOR = 32, 200
"""Points between a cut's ends tried for a plunge: one every R' along it, at least
INTERIOR and at most MAX_INTERIOR (evenly spaced by index)."""
SIDE_POINTS = 4
"""Points between a cut's ends tried for a horizontal approach (each costs 4 OCCT
distances of a swept tool)."""
OUTSIDE = 1.0
"""mm beyond R' outside the part's bounding box where a horizontal approach starts."""


class Access:
    """Whether the tool reaches a ball centre from above or from the side on ``part``
    (see the module doc), for ``job``'s tool, links at ``z_safe`` mm."""

    def __init__(self, part, job: Job, z_safe: float):
        self.part, self.job, self.z_safe = part, job, float(z_safe)
        self.lo, self.hi = (np.asarray(v, float) for v in part.bounding_box())
        self.shank = max(self.z_safe - float(self.lo[2]), job.tool.shank)
        self.limit = job.tolerances.gouge
        self._guards: dict = {}
        self._moves: MoveClearance | None = None

    def plunge(self, faces, p) -> tuple[bool, str]:
        """(clear, why not) of the straight plunge from the clearance height onto ``p``,
        the ball following ``faces`` there (their own-face rule as for the cuts)."""
        faces = tuple(f for f in faces if f is not None)
        if faces not in self._guards:
            share = FINISH_OWN_SHARE if len(faces) == 1 else PAIR_OWN_SHARE
            self._guards[faces] = guard_for(self.part, faces, self.job, shank=self.shank,
                                            own_share=share)
        margin, detail = self._guards[faces].margin(p)
        # a cut's end landed on a collision sits at margin ~0 (-1e-8 mm is landing
        # round-off): only a deeper hit blocks the way; the gate judges every move anyway
        if margin >= -self.limit:
            return True, ""
        return False, (f"({p[0]:.4f}, {p[1]:.4f}, {p[2]:.4f}): {detail} "
                       f"({-margin:.4g} mm too near) on the way to Z {self.z_safe:.3f}")

    def side(self, p) -> np.ndarray | None:
        """The point outside the part at ``p``'s height from which a horizontal approach
        onto ``p`` is clear (the first of SIDES that is), or None."""
        p = np.asarray(p, float)
        if self._moves is None:
            self._moves = MoveClearance(self.part, self.job.tool.offset, self.job.tool.shank)
        reach = self.job.tool.offset + OUTSIDE
        tol = PAIR_OWN_SHARE * self.limit
        for d in SIDES:
            d = np.asarray(d)
            k = int(np.flatnonzero(d)[0])
            edge = self.hi[k] if d[k] > 0 else self.lo[k]
            q = p.copy()
            q[k] = edge + d[k] * reach
            top = np.array([q[0], q[1], max(self.z_safe, q[2])])
            if self._moves.clear(top, q, tol) and self._moves.clear(q, p, tol):
                return q
        return None


def _indices(n: int, count: int) -> list[int]:
    """Up to ``count`` point indices strictly between 0 and n, evenly spaced, in order."""
    if n < 2:
        return []
    return sorted(set(np.linspace(0, n, count + 2).round().astype(int)[1:-1]) - {0, n})


def _piece(cut: CutSegment, lo: int, hi: int, reverse: bool) -> CutSegment:
    """Points lo..hi of ``cut`` as a cut of their own (from hi to lo when ``reverse``), its
    job's start and end its own ends. A forward piece keeps the cut's stop (it ends where
    the cut ended); a reversed one ends where the cut began, an intended end (``end``)."""
    tp = toolpath_piece(cut.path, lo, hi, reverse)
    op = replace(tp.job.operation, start=tuple(map(float, tp.points[0])),
                 end=tuple(map(float, tp.points[-1])))
    tp = replace(tp, job=replace(tp.job, operation=op))
    if reverse:
        tp = replace(tp, stop_reason=END, stop_detail="end point reached: the cut's start, "
                     "cut the other way from where it was entered")
    return CutSegment(tp, cut.edge, cut.stretch, cut.at_limit)


def _retrace(path, lo: int, hi: int, reverse: bool) -> LinkSegment:
    """Back along points lo..hi of ``path`` (already cut), at feed."""
    pts = path.points[lo:hi + 1]
    pts = pts[::-1] if reverse else pts
    return LinkSegment(pts, np.zeros(len(pts) - 1, dtype=bool))


class Outline(NamedTuple):
    """What the entry of a cut depends on: its points ((N, 3) mm), its faces and its
    length (mm); a worker's task is this, not the whole cut."""

    points: np.ndarray
    faces: tuple
    length: float


def outline(cut: CutSegment) -> Outline:
    """The :class:`Outline` of ``cut``."""
    return Outline(cut.points, cut.path.faces, cut.length)


def _entry(cut: Outline, access: Access) -> tuple[int, np.ndarray | None, str]:
    """(index, side point or None, "") of where ``cut`` is entered; (-1, None, why) when
    nowhere is clear."""
    pts, faces = cut.points, cut.faces
    n = len(pts) - 1
    first, why = access.plunge(faces, pts[0])
    if first:
        return 0, None, ""
    if n and access.plunge(faces, pts[n])[0]:
        return n, None, ""
    between = _indices(n, int(np.clip(cut.length / access.job.tool.offset, INTERIOR,
                                      MAX_INTERIOR)))
    for k in between:
        if access.plunge(faces, pts[k])[0]:
            return k, None, ""
    for k in [0, n][:1 + bool(n)] + _indices(n, SIDE_POINTS):
        q = access.side(pts[k])
        if q is not None:
            return k, q, ""
    return -1, None, (f"no clear entry: the plunge onto its start {why}; onto its end and "
                      f"{len(between)} points between, and from the side "
                      f"({', '.join(SIDE_NAMES)}) at its height: blocked too")


def entry_plan(cut: Outline, access: Access) -> tuple[int, np.ndarray | None, str, bool]:
    """Where ``cut`` is entered and whether the tool leaves straight up: (index, side
    point or None, why not, out) as :func:`_entry` gives them, ``out`` whether the plunge
    from the last point cut is clear (asked only when it decides the :class:`Visit`).
    Plain values: a worker's answer (:func:`entered_program_segments`)."""
    k, side, why = _entry(cut, access)
    if k < 0:
        return k, side, why, False
    n = len(cut.points) - 1
    last = n if k == 0 else 0
    out = side is None and (last == k or access.plunge(cut.faces, cut.points[last])[0])
    return k, side, why, out


def visit_for(cut: CutSegment, access: Access, plan=None) -> Visit | Skipped:
    """The :class:`Visit` that enters, cuts and leaves ``cut`` (module doc), or its
    :class:`Skipped` (UNREACHABLE) when no entry is clear; ``plan``: its
    :func:`entry_plan` when already known."""
    k, side, why, out = entry_plan(outline(cut), access) if plan is None else plan
    path, n = cut.path, len(cut.points) - 1
    if k < 0:
        return Skipped(path.faces, UNREACHABLE, f"cut of {path.length:.3f} mm: {why}",
                       cut.edge)
    piece = lambda lo, hi, rev: _piece(cut, lo, hi, rev)  # noqa: E731
    if k == 0:
        segments, last = [cut], n
    elif k == n:
        segments, last = [piece(0, n, True)], 0
    else:
        segments = [piece(k, n, False), _retrace(path, k, n, True), piece(0, k, True)]
        last = 0
    if out:
        return Visit(segments, None, None)
    if last != k:   # back along the cut to where the tool came in
        segments.append(_retrace(path, min(k, last), max(k, last), last > k))
    return Visit(segments, side, side)


def entered(cuts: list[CutSegment], access: Access, tick=None, plans=None
            ) -> tuple[list, list[Skipped], list[str]]:
    """Each cut as it is entered (the cut itself when a plunge onto its start and out of
    its end are clear, else its :class:`Visit`), those skipped as UNREACHABLE, and a note
    counting the cuts entered otherwise than at their start (none when every one is).
    ``tick(k, n)``: called before cut k of n is looked at (a heartbeat); ``plans``: each
    cut's :func:`entry_plan` when already known."""
    out, skipped, ways = [], [], {}
    for k, cut in enumerate(cuts):
        if tick is not None and plans is None:
            tick(k, len(cuts))
        v = visit_for(cut, access, None if plans is None else plans[k])
        if isinstance(v, Skipped):
            skipped.append(v)
            continue
        plain = len(v.segments) == 1 and v.side_in is None and v.segments[0] is cut
        out.append(cut if plain else v)
        if not plain:
            ways[_way(cut, v)] = ways.get(_way(cut, v), 0) + 1
    note = [] if not ways else ["entries: " + ", ".join(
        f"{n} cut(s) {w}" for w, n in ways.items())]
    return out, skipped, note


def _way(cut: CutSegment, v: Visit) -> str:
    """How ``v`` enters and leaves ``cut``, for the program's note."""
    if v.side_in is not None:
        k = int(np.argmax(np.abs(v.side_in[:2] - v.points[0][:2])))
        sign = "+" if v.side_in[k] > v.points[0][k] else "-"
        where = f"from the {sign}{'XY'[k]} side at its height"
    elif np.array_equal(v.points[0], cut.points[0]):
        where = "plunged onto at its start"
    elif np.array_equal(v.points[0], cut.points[-1]):
        where = "plunged onto at its end (cut the other way)"
    else:
        where = "plunged onto between its ends (cut both ways from there)"
    back = any(s.kind == "link" for s in v.segments)
    return where + (", left back along the cut" if back else "")


def entered_program_segments(part, job: Job, cuts: list[CutSegment], z_safe: float,
                             join: float = 0.0, stay_down=None, order=None, tick=None,
                             processes: int | None = 1) -> tuple[list, list[Skipped], list[str]]:
    """The segments of a program of ``cuts`` (each entered by the rule of the module doc,
    then ordered by ``order(items)`` when given, and linked), the cuts skipped, and the
    note on entries (:func:`entered`, with ``tick``). ``processes``: processes looking for
    the cuts' entries (None: every core); the answer does not depend on it."""
    items, skipped, notes = entered_items(part, job, cuts, z_safe, tick, processes)
    if order is not None:
        items = order(items)
    return linked(items, z_safe, join=join, stay_down=stay_down), skipped, notes


def entered_items(part, job: Job, cuts: list[CutSegment], z_safe: float, tick=None,
                  processes: int | None = 1) -> tuple[list, list[Skipped], list[str]]:
    """Each of ``cuts`` as it is entered (:func:`entered`: the items
    :func:`~cadcnc.program.linking.linked` links), the cuts skipped and the note on
    entries; ``processes`` look for the entries (None: every core; the same answer)."""
    access, plans = Access(part, job, z_safe), None
    if check_jobs(processes) > 1 and len(cuts) > 1:
        seen = [0]

        def told(_: int, _plan) -> None:
            seen[0] += 1
            if tick is not None:
                tick(seen[0], len(cuts))

        plans = on_workers(_plan_task, [(job, z_safe, outline(cut)) for cut in cuts], part,
                           processes, told, "the entry of cut")
    return entered(cuts, access, tick, plans)


def _plan_task(part, task, beat=None) -> tuple:
    """One cut's :func:`entry_plan` (an :func:`on_workers` task), its Access (and the
    guards it builds) shared with the process's next cut of the same part and job."""
    job, z_safe, cut = task
    held = part.derived.get(__name__)   # the last (job, z_safe, Access) on this part
    if held is None or held[0] != job or held[1] != z_safe:
        held = part.derived[__name__] = (job, z_safe, Access(part, job, z_safe))
    return entry_plan(cut, held[2])
