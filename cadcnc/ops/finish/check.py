"""A finishing pass's self-check: its cuts travel its way and cover what was planned.

A plane's pass is planned from the crossings of its offset curve with the boundaries of
the selected faces (:mod:`.crossings`) and cut piece by piece. A wrong pairing of
crossings, a piece run the wrong way or a chain ending early would still give cuts whose
every point is exact on its face, so the gate alone cannot see it. This check can:

- **direction**: along every cut the centre's coordinate s along the travel never goes
  back by more than ``BACK_MM`` where the contact's normal points up (the centre's
  curve advances along the pass direction, or its reverse for a reversed pass, exactly
  where n_z > 0: :func:`~cadcnc.ops.finish.crossings.pass_tangent`; a climbed wall
  keeps s, and past vertical the curve runs back by construction);
- **coverage**: the planned intervals of s, per face from its crossings (a sweep over
  them in their order along the pass, :func:`along_pass`: inside the face while more
  entries than exits were passed), united over the faces, lie within the union of the
  cuts' s ranges and the stretches the pass accounted for (skipped with a reason), up
  to gaps of ``GAP_MM`` (a cut landed on its boundary this near its planned end has
  reached it);
- **no overlap**: no two cuts cover the same s range by more than ``OVERLAP_MM`` (a
  stretch cut twice), every pair compared (not only neighbours in s order).

:func:`pass_problems` returns the sentences of what failed (empty when the pass is
right). Lengths mm.
"""

from __future__ import annotations

import numpy as np

BACK_MM = 1e-6      # mm: a cut may go back this much where the normal points up (module doc)
GAP_MM = 1e-3       # mm: the gap a pass may leave where a cut landed on its boundary
OVERLAP_MM = 1e-6   # mm: two cuts may share this much of the s range (round-off)
SAME_S = 1e-6
"""mm: crossings this near in s lie on one vertical stretch of the centre's curve (a wall
climbed or descended): their order along the pass is by height, not by s."""


def _union(intervals, gap: float) -> list[tuple[float, float]]:
    """The union of (a, b) intervals (a <= b), merging those less than ``gap`` apart."""
    out: list[list[float]] = []
    for a, b in sorted(intervals):
        if out and a <= out[-1][1] + gap:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return [(a, b) for a, b in out]


def along_pass(crossings, travel: np.ndarray) -> list:
    """``crossings`` (each with ``s``, ``point``, ``normal``, ``entry``) in their order along
    the pass: by s, and within a run of crossings less than ``SAME_S`` apart in s (a
    vertical stretch of the centre's curve) by height, upwards on a wall facing against
    the travel (climbed), downwards on one facing along it (descended); entries before
    exits at one point."""
    out: list = []
    group: list = []

    def flush():
        up = sum(float(c.normal @ travel) for c in group) <= 0.0   # climbed
        group.sort(key=lambda c: ((1.0 if up else -1.0) * float(c.point[2]), not c.entry))
        out.extend(group)
        group.clear()

    for c in sorted(crossings, key=lambda c: (c.s, not c.entry)):
        if group and c.s - group[-1].s > SAME_S:
            flush()
        group.append(c)
    if group:
        flush()
    return out


def planned_intervals(crossings: dict, travel: np.ndarray | None = None
                      ) -> list[tuple[float, float]]:
    """The s intervals (mm) of the plane inside the selected faces: per face (its
    crossings) a sweep in their order along the pass (:func:`along_pass`; by s alone
    without ``travel``), united over faces."""
    spans = []
    for cs in crossings.values():
        depth, start = 0, 0.0
        order = (along_pass(cs, travel) if travel is not None
                 else sorted(cs, key=lambda c: (c.s, not c.entry)))
        for c in order:
            if c.entry:
                if depth == 0:
                    start = c.s
                depth += 1
            elif depth > 0:
                depth -= 1
                if depth == 0:
                    spans.append((start, c.s))
    return _union(spans, 0.0)


def pass_problems(cuts, crossings: dict, accounted, travel: np.ndarray) -> list[str]:
    """What is wrong with one plane's ``cuts`` (CutSegments, in order) against its
    ``crossings`` (face -> Crossings) and the ``accounted`` (s0, s1) stretches skipped
    with a reason, for centres travelling along ``travel`` (3,): sentences, [] if none."""
    problems = []
    ranges = []
    for k, cut in enumerate(cuts, 1):
        s = cut.points @ travel
        ds = np.diff(s)
        if len(s) > 1:   # only where the normal points up is the curve bound to advance
            up = np.minimum(cut.path.normals[:-1, 0, 2], cut.path.normals[1:, 0, 2]) > 0.0
            ds = np.where(up, ds, 0.0)
        back = float(-ds.min()) if len(s) > 1 else 0.0
        if back > BACK_MM:
            i = int(np.argmin(ds))
            problems.append(f"cut {k} (face {cut.path.faces[0]}) goes back {back:.3g} mm "
                            f"against the travel near ({', '.join(f'{v:.3f}' for v in cut.points[i])})")
        ranges.append((float(s.min()), float(s.max())))
    order = sorted(ranges)
    reach = -np.inf   # the furthest end of the cuts before, so that no pair is missed
    for b0, b1 in order:
        if min(reach, b1) - b0 > OVERLAP_MM:
            problems.append(f"two cuts both cover s {b0:.4f} .. {min(reach, b1):.4f} mm")
        reach = max(reach, b1)
    covered = _union(ranges + [tuple(sorted(st)) for st in accounted], GAP_MM)
    for a, b in planned_intervals(crossings, travel):
        inside = any(c0 - GAP_MM <= a and b <= c1 + GAP_MM for c0, c1 in covered)
        if not inside:
            problems.append(f"the planned stretch s {a:.4f} .. {b:.4f} mm is not covered by "
                            "the cuts")
    return problems
