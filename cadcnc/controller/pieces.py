"""A program cut into the pieces the feed planner plans one by one (no OCCT).

A piece is one cut (the kernel's points, which the stream re-interpolates), one
straight move of a link, or one rounded corner of a link (``--blend``: its samples).
Pieces are grouped into runs that stop only at corners (:mod:`.runs`). Arrays: ``points``
(n, 3) mm, ``s`` (n,) arc length (chord sum) from the piece's start, mm; speeds mm/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.job import check_number
from ..interp.cycle import MAX_TURN
from ..program.blending import blend_sizes, round_link
from ..program.program import Program
from .machine import Machine
from .path_derivatives import distinct, substep_need

DUPLICATE = 1e-12   # mm: consecutive points this close are one point
ACCURACY_SHARE = 0.9
"""The planned step stays within this share of the step the accuracy rule allowed the
program (``accuracy_cycles``): the kernel then never shortens a planned step."""
STRAIGHT_K = 1e-6      # 1/mm: a path this little curved is straight (a 1 mm step's sag 1e-7 mm)
MAX_SUBSTEPS = 8
"""Kernel cycles a machine period at most on a cut whose accurate step is shorter than the
feed's step a period (one count a cut: the kernel's point error then varies smoothly with
the speed, as the jerk by finite differences needs)."""


@dataclass
class Piece:
    """One cut or one straight link move, planned as one motion from rest to rest.

    ``cap`` (mm/s): the programmed speed (inf for a rapid: the axes' limits alone);
    ``step_cap`` (n,) mm/s or None: per point, the speed at which each of the period's
    ``substeps`` kernel cycles stays within the step the accuracy rule allowed;
    ``segment`` the index in ``program.segments``, ``cut`` the index among
    ``program.cuts`` (None for a link)."""

    points: np.ndarray
    s: np.ndarray
    cap: float
    segment: int
    cut: int | None = None
    step_cap: np.ndarray | None = None
    kappa: np.ndarray | None = None   # (n,) curvature 1/mm through each point and its two
    substeps: int = 1   # kernel cycles a machine period (a cut's, :func:`substeps_for`)

    @property
    def length(self) -> float:
        return float(self.s[-1])

    @property
    def rapid(self) -> bool:
        return math.isinf(self.cap)


def _distinct(points: np.ndarray):
    """Points without consecutive duplicates, their arc length (each chord of a curve of
    curvature k an arc of h (1 + k^2 h^2 / 24): the kernel re-run at shorter steps
    follows the arc), curvature (the circle through each point and its neighbours) and
    the kept mask (:func:`.path_derivatives.distinct`)."""
    return distinct(np.ascontiguousarray(points, dtype=np.float64), DUPLICATE)


def _step_caps(seg, machine: Machine, mask: np.ndarray,
               kappa: np.ndarray) -> np.ndarray | None:
    """Per kept point, the speed (mm/s) whose step at the machine's period stays within
    ACCURACY_SHARE of what the accuracy rule allowed the program there, and of what it
    allows any step on the path's curvature ``kappa`` (the chord's sag kappa f² / 4 within
    the accuracy, a turn of at most MAX_TURN): a step the kernel shortens would leave it
    behind the plan. None if no cap. The last step (landed on the end or a limit, not
    shortened for accuracy) is not one."""
    path = seg.path
    job = path.job
    full = job.step
    commanded = np.asarray(path.commanded, dtype=float)
    n = len(commanded)
    limit = np.full(n, math.inf)
    if path.accuracy_cycles:
        short = commanded[1:-1] < full * (1.0 - 1e-9)   # step k -> k + 1 shortened
        steps = np.where(short, commanded[1:-1], math.inf)
        limit[:-2] = np.minimum(limit[:-2], steps)
        limit[1:-1] = np.minimum(limit[1:-1], steps)
    limit = limit[mask]
    # where the path bends, no step longer than the program's was ever tried (a straight
    # stretch's step lands on the path whatever its length)
    limit = np.where(kappa > STRAIGHT_K, np.minimum(limit, full), limit)
    with np.errstate(divide="ignore"):
        chord = np.minimum(np.sqrt(4.0 * job.tolerances.accuracy / kappa), MAX_TURN / kappa)
    limit = np.minimum(limit, chord)
    if not np.isfinite(limit).any():
        return None
    return ACCURACY_SHARE * limit / machine.period


def substeps_for(points: np.ndarray, s: np.ndarray, caps: np.ndarray | None, feed: float,
                 machine: Machine) -> int:
    """Kernel cycles a period (1..MAX_SUBSTEPS) for a cut whose accurate step ``caps``
    ((n,) mm/s a cycle a period) holds the speed under what the feed (mm/s) and the axes'
    velocities along its tangent allow: the fewest that lift every cap."""
    if caps is None:
        return 1
    need = substep_need(points, s, caps, feed, np.asarray(machine.max_velocity, float))
    return int(min(max(math.ceil(need - 1e-9), 1), MAX_SUBSTEPS))   # round-off of need


def pieces_of(program: Program, machine: Machine, feed: float | None = None, *,
              blend: float = 0.0, rounded: frozenset[int] = frozenset()) -> list[Piece]:
    """The program's pieces in machining order. ``feed`` (mm/min) replaces the program's
    feed for cuts and the links' feed moves; rapids go as fast as the axes allow.
    ``blend`` (mm): the corners of the links whose segment index is in ``rounded`` are
    rounded within it (:func:`rounded_link`; which links: :mod:`.link_blends`)."""
    feed = program.job.feed if feed is None else check_number("feed", feed, "mm/min")
    blend = check_number("blend", blend, "mm", allow_zero=True)
    pieces: list[Piece] = []
    cut = 0
    for k, seg in enumerate(program.segments):
        if seg.kind == "cut":
            pts, s, kappa, mask = _distinct(np.asarray(seg.points, dtype=float))
            if s[-1] > DUPLICATE:
                caps = _step_caps(seg, machine, mask, kappa)
                m = substeps_for(pts, s, caps, feed / 60.0, machine)
                pieces.append(Piece(pts, s, feed / 60.0, k, cut,
                                    None if caps is None else m * caps, kappa, m))
            cut += 1
            continue
        if k in rounded:
            pieces += rounded_link(seg, blend, feed / 60.0, k)
            continue
        pieces += link_pieces(seg, feed / 60.0, k)
    return pieces


def link_pieces(link, feed: float, segment: int) -> list[Piece]:
    """The pieces of a link as programmed: one per straight move (its chord is its arc),
    rapids unbounded, feed moves at ``feed`` mm/s."""
    moves = np.asarray(link.points, dtype=float)
    lengths = np.linalg.norm(np.diff(moves, axis=0), axis=1).tolist()
    return [Piece(moves[m:m + 2].copy(), np.array([0.0, h]),
                  math.inf if rapid else feed, segment)
            for m, (h, rapid) in enumerate(zip(lengths, link.rapid)) if h > DUPLICATE]


def rounded_link(link, blend: float, feed: float, segment: int) -> list[Piece]:
    """The pieces of a link (segment index ``segment``) with its corners rounded within
    ``blend`` mm (:func:`round_link`): straight moves and blends (a blend's samples, their
    arc length and curvature), at ``feed`` (mm/s) unless between two rapids."""
    out = []
    for move in round_link(link, blend_sizes(np.asarray(link.points, float), blend)):
        cap = math.inf if move.rapid else feed
        if not move.curved:
            h = float(np.linalg.norm(move.points[1] - move.points[0]))
            if h > DUPLICATE:
                out.append(Piece(move.points, np.array([0.0, h]), cap, segment))
            continue
        pts, s, kappa, _ = _distinct(move.points)
        out.append(Piece(pts, s, cap, segment, kappa=kappa))
    return out


def programmed_time(pieces: list[Piece], machine: Machine) -> float:
    """Seconds at the programmed feed, rapids at the axes' velocity, no ramps: the time a
    stream at constant feed takes, and what the planned stream is measured against."""
    return float(sum(p.length / constant_speed(p, machine) for p in pieces))


def constant_speed(piece: Piece, machine: Machine) -> float:
    """The programmed speed (mm/s); a rapid's is the fastest every axis allows along it."""
    if not piece.rapid:
        return piece.cap
    u = np.abs(piece.points[-1] - piece.points[0]) / piece.length
    with np.errstate(divide="ignore"):
        return float(np.min(np.asarray(machine.max_velocity) / u))
