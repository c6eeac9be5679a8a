"""Work the gates on one part share: faces, boxes, the solid classifier, exact distances.

A command gates each cut twice: the cut-back step gates it on its own points, the
program gate again on the moves written (rounded, links included). :class:`GateCache`
keeps, per part and tolerances, what the second gate (and every other gate on that
part) would compute again: OCCT's probes and the faces' boxes, the solid classifier,
every exact point-to-face distance by face and point (:meth:`PartFaces.distance`), and
the pair's checks by toolpath (keyed by content, so a worker process can be handed
them). Every value kept is OCCT's answer for the same input, so a gate answers as it
would from scratch; the reference gate (``reference=True``) keeps nothing.

The work is kept on the part (``part.derived``), and only from :func:`open_shared` on or
inside ``with shared_gates(part):`` (a command's cut-back step and program gate; a
worker's part for its pool's life); elsewhere each gate starts afresh. Nothing outlives
the part.
"""

from __future__ import annotations

import hashlib
import itertools
from contextlib import contextmanager

import numpy as np

from ..core.tolerances import Tolerances
from .material import Material, PartFaces


class GateCache:
    """What gates on ``part`` with tolerances ``tol`` share (module doc)."""

    def __init__(self, part, tol: Tolerances):
        self.memo: dict = {}
        self.faces = PartFaces(part, {}, tol, memo=self.memo)
        self.material = Material(self.faces, tol)
        self.surfaces: dict[str, list] = {}
        self.shares: dict[str, tuple] = {}  # by toolpath: what workers found (gate_jobs)

    def share(self, key: str, since: int) -> tuple:
        """(key, the pair's checks, the distances added since the memo held ``since``):
        what one gate found, to hand to another process."""
        added = dict(itertools.islice(self.memo.items(), since, None))
        return key, self.surfaces.get(key), added

    def take(self, share: tuple | None) -> None:
        """Keep what :meth:`share` handed over."""
        if share is None:
            return
        key, surfaces, added = share
        if surfaces is not None:
            self.surfaces.setdefault(key, surfaces)
        for k, v in added.items():
            self.memo.setdefault(k, v)


def cache_for(part, tol: Tolerances) -> GateCache:
    """The :class:`GateCache` of ``part`` and ``tol`` inside :func:`shared_gates` (made
    on first use), else a new one."""
    per_part = part.derived.get(__name__)
    if per_part is None:
        return GateCache(part, tol)
    if tol not in per_part:
        per_part[tol] = GateCache(part, tol)
    return per_part[tol]


def open_shared(part) -> None:
    """Keep the gates' work on ``part`` from now on (a worker's part: its pool's life)."""
    part.derived.setdefault(__name__, {})


@contextmanager
def shared_gates(part):
    """Gates on ``part`` inside the block share their work (module doc)."""
    fresh = __name__ not in part.derived
    open_shared(part)
    try:
        yield
    finally:
        if fresh:
            part.derived.pop(__name__, None)


def toolpath_key(toolpath) -> str:
    """A digest of what the pair's checks read from ``toolpath``: its centres, contact
    parameters, faces and offsets."""
    h = hashlib.sha1()
    for a in (toolpath.points, toolpath.uv):
        h.update(np.ascontiguousarray(a, float).tobytes())
    h.update(repr((toolpath.faces, toolpath.offsets)).encode())
    return h.hexdigest()
