"""Links between cuts: retract to a clearance height, rapid across, plunge at feed.

Heights are ball-centre Z in mm. A link from the end a of one cut to the start b of the
next is the polyline a -> (a.x, a.y, z_safe) -> (b.x, b.y, z_safe) -> (b.x, b.y, b.z +
approach) -> b: the retract and the move across are rapids, the last part a feed move at
the plunge feed (``approach`` mm above b, or all of the descent when z_safe is lower).
The program's first cut is reached the same way from above its start, and the last cut
leaves straight up to z_safe. Where a cut is entered or left otherwise (:class:`Visit`:
from a point outside the part at the cut's height, or along cut points retraced), the
link runs that way (:mod:`cadcnc.ops.entries` decides it). Whether a link clears the
part is decided by the gouge gate, which checks every move of the program, links
included.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .program import CutSegment, LinkSegment

APPROACH = 2.0
"""mm above a cut's start where the rapid descent ends and the plunge at feed begins."""
TWO_OPT_MAX = 150
"""2-opt (cubic per pass) is run on at most this many chains; above, nearest neighbour."""
JOINED = 1e-9
"""mm: a cut that starts where the previous one ended continues without a link."""


def _descent(xy: np.ndarray, z_from: float, z_to: float, approach: float):
    """Points and flags from (xy, z_from) down to (xy, z_to): rapid, then feed."""
    pts, rapid = [], []
    z_mid = z_to + approach
    if z_from > z_mid:
        pts.append((*xy, z_mid))
        rapid.append(True)
    pts.append((*xy, z_to))
    rapid.append(False)
    return pts, rapid


@dataclass
class Visit:
    """Cuts machined between one entry and one exit: ``segments`` (cuts, and the feed links
    retracing cut points between them), entered at the first cut's start and left at the
    last cut's end. ``side_in`` / ``side_out``: None where the tool comes straight down /
    goes straight up there, else the point (3,) mm outside the part at the same height
    from which it comes in / to which it leaves horizontally (:mod:`cadcnc.ops.entries`)."""

    segments: list
    side_in: np.ndarray | None = None
    side_out: np.ndarray | None = None

    @property
    def cuts(self) -> list[CutSegment]:
        return [s for s in self.segments if s.kind == "cut"]

    @property
    def points(self) -> np.ndarray:
        """(2, 3): where the visit starts and ends, mm (what :func:`order_cuts` reads)."""
        return np.array([self.segments[0].points[0], self.segments[-1].points[-1]])


def _visit(item) -> Visit:
    return item if isinstance(item, Visit) else Visit([item])


def _up(a: np.ndarray, side, top: float) -> tuple[list, list]:
    """Points and flags after ``a`` up to ``top``: straight up (rapid), or first out to
    ``side`` at the plunge feed then up."""
    pts, rapid, at = [], [], a
    if side is not None:
        at = np.asarray(side, dtype=float)
        pts.append(tuple(at))
        rapid.append(False)
    if top > at[2]:
        pts.append((at[0], at[1], top))
        rapid.append(True)
    return pts, rapid


def _down(b: np.ndarray, side, top: float, approach: float) -> tuple[list, list]:
    """Points and flags from above (at ``top``) down to ``b``: the descent (rapid, then
    feed for the last ``approach``) onto b, or onto ``side`` and then across to b."""
    at = b if side is None else np.asarray(side, dtype=float)
    pts, rapid = _descent(at[:2], top, at[2], approach)
    if side is not None:
        pts.append(tuple(b))
        rapid.append(False)
    return pts, rapid


def link(a: np.ndarray, b: np.ndarray, z_safe: float, approach: float = APPROACH,
         side_out=None, side_in=None) -> LinkSegment:
    """The link from point ``a`` (a cut's end) to ``b`` (the next cut's start), (3,) mm:
    up from a (or out to ``side_out`` first), across at the clearance height, down onto b
    (or onto ``side_in`` and across to b)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    top = max(z_safe, a[2], b[2])
    pts, rapid = _up(a, side_out, top)
    pts.insert(0, tuple(a))
    over_a = np.asarray(pts[-1])
    over_b = b if side_in is None else np.asarray(side_in, dtype=float)
    if over_a[2] < top:   # a or its side point lies at the top already
        pts.append((over_a[0], over_a[1], top))
        rapid.append(True)
    if np.hypot(*(over_b[:2] - over_a[:2])) > 0.0:
        pts.append((over_b[0], over_b[1], top))
        rapid.append(True)
    down, flags = _down(b, side_in, top, approach)
    return LinkSegment(np.array(pts + down), np.array(rapid + flags))


def approach(b: np.ndarray, z_safe: float, approach: float = APPROACH,
             side=None) -> LinkSegment:
    """From above ``b`` (or ``side``) at z_safe down to b (rapid, then feed for the last
    ``approach``; then across from ``side`` to b at feed)."""
    b = np.asarray(b, dtype=float)
    at = b if side is None else np.asarray(side, dtype=float)
    top = max(z_safe, at[2] + approach, b[2])
    down, flags = _down(b, side, top, approach)
    return LinkSegment(np.array([(at[0], at[1], top), *down]), np.array(flags))


def retract(a: np.ndarray, z_safe: float, side=None) -> LinkSegment:
    """From ``a`` straight up to z_safe (a rapid), or out to ``side`` first (feed)."""
    a = np.asarray(a, dtype=float)
    top = max(z_safe, a[2])
    pts, rapid = _up(a, side, top)
    if not pts:   # already at the top
        pts, rapid = [(a[0], a[1], top)], [True]
    return LinkSegment(np.array([a, *pts]), np.array(rapid))


def linked(cuts: list, z_safe: float, approach_mm: float = APPROACH,
           join: float = 0.0, stay_down=None) -> list:
    """``cuts`` in order with an approach before the first, a link between each two, and a
    retract after the last: the segments of a program. Two cuts whose gap is at most
    ``join`` mm (a chain: the next starts where the last stopped, both located to within
    their limits' accuracy) are joined by one straight feed move instead of a lift, and so
    are two cuts for which ``stay_down(a, b)`` (the end of one and the start of the next,
    (3,) mm) says that straight move is verified clear (a zigzag's pass ends). An item of
    ``cuts`` may be a :class:`Visit`: its segments in order, entered and left its way."""
    if not cuts:
        return []
    visits = [_visit(c) for c in cuts]
    first = visits[0]
    out: list = [approach(first.points[0], z_safe, approach_mm, first.side_in)]
    for k, v in enumerate(visits):
        start = v.points[0]
        prev = visits[k - 1] if k else None
        a = prev.points[-1] if prev is not None else start
        gap = float(np.linalg.norm(start - a))
        if gap > JOINED and (gap <= join or (stay_down is not None
                                             and stay_down(a, start))):
            out.append(LinkSegment(np.array([a, start]), np.array([False])))
        elif gap > JOINED:
            out.append(link(a, start, z_safe, approach_mm, prev.side_out, v.side_in))
        out += v.segments
    last = visits[-1]
    out.append(retract(last.points[-1], z_safe, last.side_out))
    return out


def _travel(a: np.ndarray, b: np.ndarray) -> float:
    """Cost of moving from a cut's end a to the next cut's start b: 0 for a chain, else the
    horizontal distance (the lift and plunge are the same for every order)."""
    return float(np.hypot(*(b[:2] - a[:2])))


def order_cuts(cuts: list[CutSegment], join: float = 0.0) -> list[CutSegment]:
    """``cuts`` reordered (each keeps its direction) to shorten the travel between them:
    chains first (a cut starting within ``join`` of another's end follows it), then nearest
    neighbour from the first cut, then 2-opt on the sequence of chains."""
    if len(cuts) < 2:
        return list(cuts)
    starts = np.array([c.points[0] for c in cuts])
    ends = np.array([c.points[-1] for c in cuts])
    nxt: dict[int, int] = {}
    taken: set[int] = set()
    for i in range(len(cuts)):  # chains: i's end meets j's start
        d = np.linalg.norm(starts - ends[i], axis=1)
        d[i] = np.inf
        for j in np.argsort(d):
            if d[j] > join:
                break
            if j not in taken:
                nxt[i] = int(j)
                taken.add(int(j))
                break
    heads = [i for i in range(len(cuts)) if i not in taken] or [0]
    chains = []
    seen: set[int] = set()
    for h in heads + list(range(len(cuts))):
        if h in seen:
            continue
        chain = [h]
        seen.add(h)
        while chain[-1] in nxt and nxt[chain[-1]] not in seen:
            chain.append(nxt[chain[-1]])
            seen.add(chain[-1])
        chains.append(chain)
    first = lambda ch: starts[ch[0]]  # noqa: E731
    last = lambda ch: ends[ch[-1]]  # noqa: E731
    order = [chains.pop(0)]
    while chains:  # nearest neighbour
        k = min(range(len(chains)), key=lambda m: _travel(last(order[-1]), first(chains[m])))
        order.append(chains.pop(k))
    improved = len(order) <= TWO_OPT_MAX
    while improved:  # 2-opt on chains kept in their direction: reverse the visiting order
        improved = False
        for i in range(1, len(order) - 1):
            for j in range(i + 1, len(order)):
                before = _travel(last(order[i - 1]), first(order[i]))
                after = _travel(last(order[i - 1]), first(order[j]))
                if j + 1 < len(order):
                    before += _travel(last(order[j]), first(order[j + 1]))
                    after += _travel(last(order[i]), first(order[j + 1]))
                inner_before = sum(_travel(last(order[m]), first(order[m + 1]))
                                   for m in range(i, j))
                inner_after = sum(_travel(last(order[m + 1]), first(order[m]))
                                  for m in range(i, j))
                if after + inner_after < before + inner_before - 1e-9:
                    order[i:j + 1] = order[i:j + 1][::-1]
                    improved = True
    return [cuts[k] for chain in order for k in chain]
