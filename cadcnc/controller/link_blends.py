"""Which links the stream rounds (``--blend MM``): those whose rounded corners plan faster
(no OCCT).

A blend lets the machine pass a link's corner without stopping, but at the speed the
curve's curvature allows, and the planner holds that speed a little before and after it
(:mod:`.run_plan`, the speed limits eroded over the averaging window). On a slow machine
a small blend can so cost more than the stop it replaces. Each link is therefore planned
on its own both ways, from rest to rest, and rounded only when that is faster: a blend
never lengthens a link's plan. Cuts and the corners where a link meets a cut are never
rounded (:mod:`cadcnc.program.blending`).
"""

from __future__ import annotations

from ..core.job import check_number
from ..program.program import Program
from .feed_plan import plan_feed
from .machine import Machine
from .pieces import Piece, link_pieces, pieces_of, rounded_link


def links_to_round(program: Program, machine: Machine, feed: float, blend: float,
                   exact: frozenset[int] = frozenset()) -> frozenset[int]:
    """Segment indices of the links whose corners rounded within ``blend`` mm plan faster
    than their exact corners (``feed`` mm/min; links in ``exact`` stay exact)."""
    if blend <= 0.0:
        return frozenset()
    out = set()
    for k, seg in enumerate(program.segments):
        if seg.kind != "link" or k in exact:
            continue
        rounded = rounded_link(seg, blend, feed / 60.0, k)
        plain = link_pieces(seg, feed / 60.0, k)
        if len(rounded) > len(plain) and (plan_feed(rounded, machine).duration
                                          < plan_feed(plain, machine).duration):
            out.add(k)
    return frozenset(out)


def stream_pieces(program: Program, machine: Machine, feed: float | None = None,
                  blend: float = 0.0, exact: frozenset[int] = frozenset()) -> list[Piece]:
    """The pieces the stream plans: the program's, with the links that pay for it rounded
    within ``blend`` mm (:func:`links_to_round`). ``blend`` 0: the program's own pieces."""
    blend = check_number("blend", blend, "mm", allow_zero=True)
    feed = program.job.feed if feed is None else check_number("feed", feed, "mm/min")
    return pieces_of(program, machine, feed, blend=blend,
                     rounded=links_to_round(program, machine, feed, blend, exact))
