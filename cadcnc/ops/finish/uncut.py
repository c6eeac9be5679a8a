"""What a finishing program left uncut: its largest scallop and the area not machined.

Measured on the samples of the selected faces the planes were placed from
(:class:`~cadcnc.ops.finish.plan.FaceSamples`, each standing for its share of the area),
against the program's actual cut points (ball centres), with a k-d tree:

- **leftover** at a sample p (normal N): how far the material left over p reaches along N,
  i.e. the smallest t >= 0 at which p + C N + t N enters a ball of radius R at a cut
  point (allowance C; sampled: the cut points themselves, so it overstates the leftover
  by at most f^2 / (8 R) between two points f apart along a pass, 0.4 µm at 0.1 mm, R 3).
- **scallop** of a sample: the cusp height between the two neighbouring passes either
  side of its ideal centre p + R' N: the nearest cut point on each side, their distance
  across the pass (the pass tangent N x n taken out), inverted through the circle model of
  :func:`~cadcnc.ops.finish.plan.centre_chord` with the surface's curvature across the
  passes at p. The largest over the machined samples is the reported scallop height.
- **left unmachined**: a sample whose leftover exceeds ``UNMACHINED`` times the scallop
  limit L (the height asked for, or the flat-floor cusp of the stepover): what a missing
  pass leaves. Its reason: the plan's (normals pointing down: ``unreachable``; concave
  tighter than the ball: ``too tight``; a wall within 5 deg of parallel to the planes:
  ``parallel wall``), else the tool at the sample's ideal centre hitting another face or
  with its shank (``unreachable``), else ``parallel wall`` where the face slopes more
  across the passes than along them (the planes too far apart on it), else ``too steep``
  where it is within ``STEEP_DEG`` of vertical (the pass climbs it), else ``missed`` (a
  pass stopped or failed there: see the passes' own skipped records). Areas mm^2, heights mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from ...guard.clearance import ClearanceGuard
from ...parallel.tasks import on_workers
from ...program.program import Skipped
from .plan import across, centre_chord, stepover_scallop

UNMACHINED = 4.0
"""A sample whose leftover exceeds this many scallop limits is left unmachined."""
STEEP_DEG = 10.0
"""deg: a face this near vertical, not parallel to the planes, is too steep to climb."""
CUSP_SLACK = 1e-6  # mm: a cusp over the limit by no more than this is within it (round-off)
NEIGHBOURS = 64  # cut points looked at around each sample's ideal centre
CHUNK = 2048     # samples measured at a time
GUARD_SAMPLES = 200  # per face and reason: samples whose tool is checked against the part
WHY = {
    "unreachable": "normals pointing down: the ball cannot reach it from +Z",
    "collision": "the shank or another face is in the way",
    "too tight": "concave tighter than the ball across the passes",
    "parallel wall": "a wall near parallel to the guide planes: the passes are too far "
                     "apart on it",
    "too steep": "too steep for the pass direction",
    "missed": "passes stopped or failed there (see the passes' skipped records)",
    "flat": "within 5 deg of horizontal: left to raster (waterline levels do not cut it)",
}


@dataclass
class UncutReport:
    """Largest scallop (mm), the limit L and unmachined threshold (mm), areas (mm^2):
    sampled, ``unmachined`` {(face, reason): area}."""

    limit: float
    threshold: float
    max_scallop: float
    max_leftover: float
    area: float
    over_limit_area: float
    unmachined: dict = field(default_factory=dict)
    n_samples: int = 0
    spacing: float = 0.0

    @property
    def unmachined_area(self) -> float:
        return float(sum(self.unmachined.values()))

    def by_reason(self) -> dict[str, float]:
        out: dict[str, float] = {}
        for (_, why), a in self.unmachined.items():
            out[why] = out.get(why, 0.0) + a
        return out

    def skipped(self) -> list[Skipped]:
        """One record per face and reason of the area left unmachined."""
        return [Skipped((face, None), "unreachable" if why == "collision" else why,
                        f"face {face}: {a:.2f} mm^2 left unmachined ({WHY[why]})")
                for (face, why), a in sorted(self.unmachined.items())]

    def notes(self) -> list[str]:
        why = ", ".join(f"{r} {a:.2f} mm^2" for r, a in sorted(self.by_reason().items()))
        return [f"uncut (sampled on {self.n_samples} points about {self.spacing:.3g} mm "
                f"apart): largest scallop {self.max_scallop:.4g} mm (limit "
                f"{self.limit:.4g} mm), {self.over_limit_area:.2f} mm^2 over the limit; "
                f"left unmachined {self.unmachined_area:.2f} of {self.area:.2f} mm^2"
                + (f" ({why})" if why else "")]


def scallop_limit(job) -> float:
    """L (mm): the scallop height asked for, or the flat-floor cusp of the stepover."""
    op = job.operation
    if op.scallop is not None:
        return op.scallop
    spacing = max(s for s in (getattr(op, "stepover", None), getattr(op, "stepdown", None))
                  if s is not None)
    return stepover_scallop(spacing, job.tool.radius)


def uncut_report(program, part, samples, plan, jobs: int = 1) -> UncutReport:
    """What ``program``'s cuts left on ``samples`` of its faces (see the module doc);
    ``plan`` the :class:`~cadcnc.ops.finish.plan.PlanePlan` they came from; ``jobs``
    processes measure the samples (the same answers)."""
    tasks = uncut_tasks([c.points for c in program.cuts], program.job, samples, plan, jobs)
    rows = on_workers(measured_rows, tasks, part, jobs, what="the uncut report's block")
    return uncut_from_rows(rows, program.job, part, samples, plan)


def uncut_tasks(cut_points: list[np.ndarray], job, samples, plan, blocks: int) -> list[tuple]:
    """The tasks of :func:`measured_rows`: ``samples`` in ``blocks`` runs of rows, each
    with every cut point ((M_k, 3) ball centres, mm, in program order) and the planes'
    normal (``plan``) and the samples' curvature across the passes; none without cuts."""
    if not cut_points:
        return []
    pts, nrm, tool = np.vstack(cut_points), samples.normals, job.tool
    q = samples.points + tool.offset * nrm
    base = samples.points + tool.allowance * nrm
    k, _ = across(samples, plan.normal)
    edges = np.linspace(0, len(q), max(1, min(blocks, len(q))) + 1).astype(int)
    return [(pts, q[a:b], base[a:b], nrm[a:b], k[a:b], plan.normal, tool.radius,
             tool.allowance, tool.offset) for a, b in zip(edges[:-1], edges[1:])]


def measured_rows(part, task, beat=None) -> tuple[np.ndarray, np.ndarray]:
    """(leftover, scallop: NaN where a side has no pass), each (N,), of one block of
    :func:`uncut_tasks` (an :func:`~cadcnc.parallel.tasks.on_workers` task; the part is
    not used): the cut points' k-d tree asked for the NEIGHBOURS nearest within R' of
    each ideal centre."""
    pts, q, base, nrm, k, n, radius, allowance, r1 = task
    tree, kk = cKDTree(pts), min(NEIGHBOURS, len(pts))
    leftover, chord, ok = np.empty(len(q)), np.zeros(len(q)), np.zeros(len(q), dtype=bool)
    for a in range(0, len(q), CHUNK):   # rows are independent; a chunk stays in cache
        b = slice(a, a + CHUNK)
        dist, idx = tree.query(q[b], k=kk, distance_upper_bound=r1)
        dist, idx = dist.reshape(len(q[b]), -1), idx.reshape(len(q[b]), -1)
        found = np.isfinite(dist)
        c = np.take(pts, np.where(found, idx, 0), axis=0)              # (n, K, 3)
        leftover[b] = _leftover(c, found, base[b], nrm[b], radius)
        chord[b], ok[b] = _chords(c, dist, q[b], nrm[b], n)
    # elementwise: one bisection over every row (fewer, longer array operations)
    return leftover, np.where(ok, _scallop_of_chord(chord, k, radius, allowance), np.nan)


def uncut_from_rows(rows: list[tuple], job, part, samples, plan) -> UncutReport:
    """The report of ``samples`` from the :func:`measured_rows` of its blocks, in order
    (none: no cut, every sample left over); ``plan`` the planes' PlanePlan."""
    limit = scallop_limit(job)
    threshold = UNMACHINED * limit
    n = plan.normal
    leftover = np.full(len(samples), np.inf)
    scallop = np.full(len(samples), np.nan)
    if rows:
        leftover, scallop = (np.concatenate(x) for x in zip(*rows))
    reason = np.array(plan.reason, dtype=object)
    machined = (leftover <= threshold) & (reason == "")
    area = samples.areas
    cusp = np.where(machined & np.isfinite(scallop), scallop, 0.0)
    report = UncutReport(limit, threshold, float(cusp.max(initial=0.0)),
                         float(leftover[machined].max(initial=0.0)), float(area.sum()),
                         float(area[machined & (cusp > limit + CUSP_SLACK)].sum()),
                         n_samples=len(samples), spacing=samples.spacing)
    left = ~machined
    q = samples.points + job.tool.offset * samples.normals
    why = _reasons(reason, left, samples, q, part, job, n)
    for face in np.unique(samples.faces[left]):
        for r in np.unique(why[left & (samples.faces == face)]):
            sel = left & (samples.faces == face) & (why == r)
            report.unmachined[(int(face), str(r))] = float(area[sel].sum())
    return report


def _leftover(c, found, base, nrm, radius: float) -> np.ndarray:
    """(N,) the smallest t >= 0 with base + t N inside a ball of radius R at a found
    centre (inf when none)."""
    w = c - base[:, None, :]
    a = np.einsum("nkj,nj->nk", w, nrm)
    b2 = np.einsum("nkj,nkj->nk", w, w) - a * a
    inside = found & (b2 < radius * radius)
    t = np.where(inside, a - np.sqrt(np.maximum(radius * radius - b2, 0.0)), np.inf)
    return np.maximum(t.min(axis=1), 0.0)


def _chords(c, dist, q, nrm, n) -> tuple[np.ndarray, np.ndarray]:
    """(chord, ok), each (N,): the distance across the passes (mm) between the nearest cut
    points either side of each sample's ideal centre q across the planes, and whether
    both sides have one (``dist`` is inf where a neighbour was not found)."""
    side = (c - q[:, None, :]) @ n                                        # (N, K)
    lo = np.where(side <= 0, dist, np.inf).argmin(axis=1)
    hi = np.where(side > 0, dist, np.inf).argmin(axis=1)
    rows = np.arange(len(q))
    ok = np.isfinite(dist[rows, lo]) & (side[rows, lo] <= 0) & np.isfinite(
        dist[rows, hi]) & (side[rows, hi] > 0)
    v = c[rows, hi] - c[rows, lo]
    t = np.cross(nrm, n)
    tn = np.linalg.norm(t, axis=1)
    ok &= tn > 1e-9   # the normals not parallel (a direction exists)
    t = t / np.maximum(tn, 1e-300)[:, None]   # no / 0 (rows dropped above)
    v = v - np.einsum("nj,nj->n", v, t)[:, None] * t
    return np.linalg.norm(v, axis=1), ok


def _scallop_of_chord(chord, k, radius: float, allowance: float) -> np.ndarray:
    """(N,) the cusp height h with centre_chord(h, k) == chord (bisection on [0, R])."""
    lo, hi = np.zeros_like(chord), np.full_like(chord, radius)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        wide = centre_chord(mid, k, radius, allowance) < chord
        lo, hi = np.where(wide, mid, lo), np.where(wide, hi, mid)
    return hi


def _reasons(reason, left, samples, q, part, job, n) -> np.ndarray:
    """(N,) the reason of each sample left unmachined (see the module doc)."""
    why = np.where(reason == "", "missed", reason).astype(object)
    open_ = left & (reason == "")
    for face in np.unique(samples.faces[open_]):
        idx = np.nonzero(open_ & (samples.faces == face))[0]
        guard = ClearanceGuard(part, (int(face), int(face)), job.tool.offset,
                               job.tool.shank, job.tolerances.hit)
        # one probe per cell of side R' (the tool's scale), at most GUARD_SAMPLES
        cells = np.floor(q[idx] / max(job.tool.offset, 1e-3)).astype(np.int64)  # mm: no / 0
        probe = idx[np.sort(np.unique(cells, axis=0, return_index=True)[1])]
        probe = probe[np.linspace(0, len(probe) - 1, min(len(probe), GUARD_SAMPLES)).astype(int)]
        hit = np.array([guard.margin(q[i])[0] < 0.0 for i in probe])
        # every sample takes the verdict of the nearest probed one
        nearest = cKDTree(q[probe]).query(q[idx])[1]
        why[idx[hit[nearest]]] = "collision"
    nrm = samples.normals
    if abs(n[2]) == 1.0:   # waterline levels: a miss is a miss
        return why
    facing_across = np.abs(nrm @ n) > np.abs(nrm @ np.cross(n, (0.0, 0.0, 1.0)))
    steep = np.abs(nrm[:, 2]) < math.sin(math.radians(STEEP_DEG))
    still = open_ & (why == "missed")
    why[still & facing_across] = "parallel wall"
    why[still & ~facing_across & steep] = "too steep"
    return why
