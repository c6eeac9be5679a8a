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


def linked_cuts(items: list) -> list[CutSegment]:
    """The cuts of :func:`linked` ``(items, ...)``, in its order (known before linking)."""
    return [s for item in items for s in _visit(item).cuts]


def _chains(starts: np.ndarray, ends: np.ndarray, join: float) -> list[list[int]]:
    """Cut indices grouped into chains (a cut starting within ``join`` mm of another's end
    follows it; among several, the nearest not yet taken), heads in index order first.
    ``starts``, ``ends``: (n, 3) mm."""
    n = len(starts)
    nxt: dict[int, int] = {}
    taken: set[int] = set()
    for i in range(n):  # chains: i's end meets j's start
        d = np.linalg.norm(starts - ends[i], axis=1)
        d[i] = np.inf
        if (d > join).all():   # no candidate: the scan below would stop at its first
            continue
        for j in np.argsort(d):
            if d[j] > join:
                break
            if j not in taken:
                nxt[i] = int(j)
                taken.add(int(j))
                break
    heads = [i for i in range(n) if i not in taken] or [0]
    chains = []
    seen: set[int] = set()
    for h in heads + list(range(n)):
        if h in seen:
            continue
        chain = [h]
        seen.add(h)
        while chain[-1] in nxt and nxt[chain[-1]] not in seen:
            chain.append(nxt[chain[-1]])
            seen.add(chain[-1])
        chains.append(chain)
    return chains


def _travels(ends: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Cost of moving from each end (m, 2+) to each start (k, 2+), (m, k): the horizontal
    distance (the lift and plunge are the same for every order; a chain is inside a
    chain). The same float as ``np.hypot`` of each one pair's differences."""
    dx = starts[None, :, 0] - ends[:, None, 0]
    dy = starts[None, :, 1] - ends[:, None, 1]
    return np.hypot(dx, dy)


def _nearest_neighbour(firsts: np.ndarray, lasts: np.ndarray) -> np.ndarray:
    """Chain order from chain 0, each next the nearest of those left (the first of equals
    in index order). ``firsts``, ``lasts``: (m, 3) mm, each chain's start and end."""
    order, rest = [0], np.arange(1, len(firsts))
    while rest.size:
        k = int(np.argmin(_travels(lasts[order[-1]][None], firsts[rest])[0]))
        order.append(int(rest[k]))
        rest = np.delete(rest, k)
    return np.array(order)


def _first_gain(d: np.ndarray, o: np.ndarray, i: int, j0: int) -> int:
    """The first j >= j0 for which reversing ``o[i:j + 1]`` shortens the travel by more
    than 1e-9 mm, or -1. ``d``: (m, m) travels between chains, ``o``: (m,) the order.
    Each sum adds the same floats in the same order as a loop over one (i, j) would."""
    m = len(o)
    fwd = np.cumsum(d[o[i:-1], o[i + 1:]])         # travel inside o[i..j], j = i+1..m-1
    rev = np.cumsum(d[o[i + 1:], o[i:-1]])         # the same, reversed
    js = np.arange(j0, m)
    tail_before = np.zeros(len(js))
    tail_after = np.zeros(len(js))
    tail_before[:-1] = d[o[js[:-1]], o[js[:-1] + 1]]
    tail_after[:-1] = d[o[i], o[js[:-1] + 1]]
    before = d[o[i - 1], o[i]] + tail_before
    after = d[o[i - 1], o[js]] + tail_after
    better = after + rev[js - i - 1] < before + fwd[js - i - 1] - 1e-9  # mm: no swap on ties
    hit = np.flatnonzero(better)
    return int(js[hit[0]]) if hit.size else -1


def _two_opt(d: np.ndarray, o: np.ndarray) -> np.ndarray:
    """``o`` improved by 2-opt (first improvement, i then j ascending, passes until none):
    a stretch of chains, each kept in its direction, visited in reverse order."""
    o = o.copy()
    improved = True
    while improved:
        improved = False
        for i in range(1, len(o) - 1):
            j = _first_gain(d, o, i, i + 1)
            while j >= 0:
                o[i:j + 1] = o[i:j + 1][::-1].copy()
                improved = True
                j = _first_gain(d, o, i, j + 1) if j + 1 < len(o) else -1
    return o


def order_cuts(cuts: list[CutSegment], join: float = 0.0) -> list[CutSegment]:
    """``cuts`` reordered (each keeps its direction) to shorten the travel between them:
    chains first (a cut starting within ``join`` of another's end follows it), then nearest
    neighbour from the first cut, then 2-opt on the sequence of chains (at most
    ``TWO_OPT_MAX`` of them)."""
    if len(cuts) < 2:
        return list(cuts)
    starts = np.array([c.points[0] for c in cuts])
    ends = np.array([c.points[-1] for c in cuts])
    chains = _chains(starts, ends, join)
    firsts = starts[[ch[0] for ch in chains]]
    lasts = ends[[ch[-1] for ch in chains]]
    order = _nearest_neighbour(firsts, lasts)
    if len(order) <= TWO_OPT_MAX:
        order = _two_opt(_travels(lasts, firsts), order)
    return [cuts[k] for c in order for k in chains[c]]
