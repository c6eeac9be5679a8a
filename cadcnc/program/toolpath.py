"""A computed toolpath: arrays per cycle, the job that produced it and why it stopped.

Shapes (N = number of points, row 0 the start): points (N, 3) cutter centres in mm;
contacts (N, 2, 3) contact points on surface 1 and 2; normals (N, 2, 3); uv (N, 2, 2) the
contacts' native (u, w) parameters; steps (N,) the length of the step that led to each
point (0 for the start), commanded (N,) the step f the cycle was commanded (mm): F Ts, or
less where the accuracy rule shortened it (``accuracy_cycles``, ``accuracy_ratio``) or the
last step landed on the end or a limit.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from ..core.job import Job
from ..interp.bounds_compiled import pair_bounds
from ..interp.cycle import CLOSED, END, PAPER_INVERSE_LIMIT
from ..interp.error_bounds import SurfaceBounds
from ..interp.record import PathRecord

INTENDED_STOPS = (END, CLOSED)
"""Stops that end a path where it was meant to end; any other stop leaves it partial."""


@dataclass
class Toolpath:
    points: np.ndarray
    contacts: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    steps: np.ndarray
    commanded: np.ndarray
    job: Job
    stop_reason: str
    stop_detail: str = ""
    bounds: tuple[SurfaceBounds, SurfaceBounds] | None = None
    accuracy_cycles: int = 0      # cycles whose step was shortened to keep tol.accuracy
    accuracy_ratio: float = 1.0   # the smallest shortened step / commanded step F Ts
    expected_length: float | None = None  # mm: the followed edge's length, when known

    def __len__(self) -> int:
        return len(self.points)

    def __repr__(self) -> str:
        return (f"<Toolpath {len(self)} points, {self.length:.3f} mm, faces {self.faces}, "
                f"stop: {self.stop_reason}>")

    @property
    def faces(self) -> tuple[int | None, int | None]:
        """The two face numbers followed (None for a face given directly)."""
        return self.job.operation.faces

    @property
    def offsets(self) -> tuple[float, float]:
        """Each surface's offset R' (mm), as the job resolved it."""
        return self.job.offsets

    @property
    def complete(self) -> bool:
        """True when the path stopped where it was meant to (its end, or once around)."""
        return self.stop_reason in INTENDED_STOPS

    @property
    def partial_reason(self) -> str:
        """Why the path stopped short, for the user ('' when it is complete), e.g.
        "stopped at 5.900 of 97.8 mm (the edge's length): diverged: surface 2: ..."."""
        if self.complete:
            return ""
        where = (f"stopped at {self.length:.3f} of {self.expected_length:.1f} mm (the edge's "
                 "length)" if self.expected_length else f"stopped after {self.length:.3f} mm")
        return f"{where}: {self.stop_reason}: {self.stop_detail}"

    @property
    def accuracy_note(self) -> str:
        """"feed reduced on N cycles to X % for accuracy", or '' when no step was shortened."""
        if not self.accuracy_cycles:
            return ""
        return (f"feed reduced on {self.accuracy_cycles} of {len(self) - 1} cycles to "
                f"{100.0 * self.accuracy_ratio:.3g} % for accuracy "
                f"({self.job.tolerances.accuracy:g} mm)")

    @property
    def length(self) -> float:
        """Polyline length through the cutter centres, mm."""
        return float(self.steps.sum())

    @property
    def duration(self) -> float:
        """Machining time in s: one interpolation period per cycle."""
        return (len(self) - 1) * self.job.period

    @property
    def tangents(self) -> np.ndarray:
        """(N, 3) unit n1 x n2 at each point, signed along the direction of travel."""
        m = np.cross(self.normals[:, 0], self.normals[:, 1])
        m /= np.linalg.norm(m, axis=1)[:, None]
        if len(self) > 1:
            d = np.diff(self.points, axis=0)
            d = np.vstack([d, d[-1:]])
            along = np.einsum("ij,ij->i", m, d)
            m *= (np.sign(along) + (along == 0))[:, None]
        return m

    @property
    def worst_predicted_mm(self) -> float:
        """Largest steady-state error bound (eq. 16) over both surfaces, mm."""
        if self.bounds is None:
            return float("nan")
        vals = np.concatenate([b.eq16[:-1] if len(b.eq16) > 1 else b.eq16 for b in self.bounds])
        return float(vals.max()) if len(vals) else float("nan")


def toolpath_from_record(record: PathRecord, job: Job, stop_reason: str,
                         stop_detail: str = "", expected_length: float | None = None
                         ) -> Toolpath:
    """Arrays (copied) and the paper's error bounds from the stepper's per-cycle record.

    The accuracy rule's count and smallest ratio come from the record's ``ratio`` column;
    ``expected_length`` (mm) is the length of the edge the path follows, if it does.
    """
    ratio = record.ratio[1:]
    short = ratio < 1.0
    path = Toolpath(
        points=record.points.copy(), contacts=record.contacts.copy(),
        normals=record.normals.copy(), uv=record.uv.copy(), steps=record.steps.copy(),
        commanded=record.commanded.copy(), job=job, stop_reason=stop_reason,
        stop_detail=stop_detail, accuracy_cycles=int(short.sum()),
        accuracy_ratio=float(ratio[short].min()) if short.any() else 1.0,
        expected_length=expected_length)
    path.bounds = compute_bounds(path, record.ru, record.rw, record.forms)
    return path


def compute_bounds(path: Toolpath, ru: np.ndarray, rw: np.ndarray,
                   forms: np.ndarray) -> tuple[SurfaceBounds, SurfaceBounds]:
    """Per point, the bounds for the step leaving it (f = the next cycle's commanded step).

    ``ru``, ``rw`` (N, 2, 3) and ``forms`` (N, 2, 6: E, F, G, L, M, N) per surface; both
    surfaces in one compiled pass (``interp.bounds_compiled``, the same numbers as the
    numpy reference ``error_bounds.pair_bounds``).
    """
    f = np.append(path.commanded[1:], path.commanded[-1] if len(path) > 1 else 0.0)
    out = pair_bounds(np.asarray(path.offsets, dtype=float), path.points, path.contacts,
                      path.normals, ru, rw, forms, path.tangents, f, PAPER_INVERSE_LIMIT)
    return SurfaceBounds(*out[0]), SurfaceBounds(*out[1])


def toolpath_head(path: Toolpath, n: int, stop_reason: str, stop_detail: str) -> Toolpath:
    """The first ``n`` points of ``path`` (n >= 2) as a toolpath of their own, stopped for
    ``stop_reason``: a cut cut back to its last verified point."""
    if not 2 <= n <= len(path):
        raise ValueError(f"a cut back path needs 2..{len(path)} points, got {n}")
    return replace(toolpath_piece(path, 0, n - 1), stop_reason=stop_reason,
                   stop_detail=stop_detail)


POINT_FIELDS = ("eps", "k", "k_max", "k_min", "tau")
"""Fields of :class:`SurfaceBounds` that describe a point (the others bound the step
leaving it)."""


def toolpath_piece(path: Toolpath, lo: int, hi: int, reverse: bool = False) -> Toolpath:
    """Points ``lo``..``hi`` (inclusive, lo < hi) of ``path`` as a toolpath of their own,
    run from hi back to lo when ``reverse``: the same positions, so every check of the
    path holds for the piece. Reversed, a point's step is the same chord run the other way
    (``steps``, ``commanded`` shifted by one; the start keeps the path's first row), and
    the bound of the step leaving a point is the forward bound of that same chord
    (computed at its other end); point properties (``POINT_FIELDS``) stay with their
    points."""
    if not 0 <= lo < hi < len(path):
        raise ValueError(f"a piece of a {len(path)}-point path needs 0 <= lo < hi < "
                         f"{len(path)}, got {lo}, {hi}")
    sl = slice(lo, hi + 1)
    if not reverse:
        pick = lambda a: a[sl]  # noqa: E731
        chord = pick
        run = lambda a: np.concatenate([a[:1], a[lo + 1:hi + 1]])  # noqa: E731
    else:
        pick = lambda a: a[sl][::-1]  # noqa: E731
        chord = lambda a: np.append(a[lo:hi][::-1], a[lo])  # noqa: E731
        run = lambda a: np.concatenate([a[:1], a[lo + 1:hi + 1][::-1]])  # noqa: E731
    bounds = None if path.bounds is None else tuple(
        replace(b, **{f.name: (pick if f.name in POINT_FIELDS else chord)(getattr(b, f.name))
                      for f in fields(b)}) for b in path.bounds)
    return replace(path, points=pick(path.points), contacts=pick(path.contacts),
                   normals=pick(path.normals), uv=pick(path.uv), steps=run(path.steps),
                   commanded=run(path.commanded), bounds=bounds)
