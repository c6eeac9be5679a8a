"""What a pencil setup reaches, counted in positions (:mod:`.fewest_setups`).

The part's concave shared edges (of the selected faces) are sampled every SPACING mm
along their length; a cut point (ball centre, part coordinates) reaches the position of
its corner nearest to it, within REACH_RADII R'. A blend corner (two faces sharing no
edge) counts its ball centres on a VOXEL mm grid instead. Keys: (pair, index) or (pair,
voxel). Lengths mm.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ...core.job import Job
from ...geometry.edge_curve import EdgeCurve
from ...geometry.part import CONCAVE, Part
from ...program.program import Program

SPACING = 0.5      # mm between two positions along a concave edge
REACH_RADII = 5.0  # a ball centre farther than this many R' from its corner's edge counts nothing
VOXEL = 1.0        # mm: the grid of a blend corner's positions
DENSE = 0.1        # mm between the points keyed along a line of feasible samples (a cut's step)


def edge_positions(part: Part, job: Job) -> dict[tuple[int, int], list]:
    """Per concave pair (i < j) of the selected faces, per concave edge (its index among
    the pair's, as a corner's ``edge``) its positions (M, 3), mm."""
    faces = None if job.operation.faces is None else set(job.operation.faces)
    out: dict = {}
    for pair, edges in part.adjacency.items():
        if faces is not None and not set(pair) <= faces:
            continue
        concave = [e for e in edges if e.edge_class == CONCAVE]
        for k, e in enumerate(concave):
            curve = EdgeCurve(e)
            n = max(int(np.ceil(curve.length / SPACING)), 1)
            pts = [curve.point_tangent(s)[0] for s in np.linspace(0.0, curve.length, n + 1)]
            out.setdefault(pair, []).append((k, np.array(pts)))
    return out


def corner_positions(part: Part, job: Job) -> dict[tuple[int, int], np.ndarray]:
    """Per concave pair (i < j) of the selected faces, its edges' positions (M, 3), mm."""
    return {pair: np.concatenate([pts for _, pts in edges])
            for pair, edges in edge_positions(part, job).items()}


def cut_keys(program: Program, samples: dict, job: Job) -> list[list]:
    """Per cut of ``program`` (part coordinates), per point its position key or None."""
    trees: dict = {}
    return [_point_keys(tuple(sorted(cut.path.faces)), cut.points, samples, trees, job)
            for cut in program.cuts]


def line_keys(lines: dict, samples: dict, job: Job) -> set:
    """The positions the polylines of feasible centres ``lines`` (per pair, part
    coordinates) reach: their points every DENSE mm keyed as a cut's points."""
    trees: dict = {}
    out: set = set()
    for pair, pair_lines in lines.items():
        for line in pair_lines:
            out.update(_point_keys(pair, _dense(line), samples, trees, job))
    out.discard(None)
    return out


def _dense(line: np.ndarray) -> np.ndarray:
    """``line``'s vertices and points between them at most DENSE mm apart."""
    pts = [line[:1]]
    for a, b in zip(line[:-1], line[1:]):
        n = max(int(np.ceil(np.linalg.norm(b - a) / DENSE)), 1)
        pts.append(a + np.outer(np.arange(1, n + 1) / n, b - a))
    return np.concatenate(pts)


def _point_keys(pair: tuple[int, int], pts: np.ndarray, samples: dict, trees: dict,
                job: Job) -> list:
    """Per point of a cut (or a line of samples) of ``pair``, its position key or None:
    its corner's nearest position within REACH_RADII R', or on a blend corner its VOXEL."""
    if pair not in samples:   # a blend corner: its ball centres on a grid
        return [(pair, tuple(np.round(p / VOXEL).astype(int))) for p in pts]
    if pair not in trees:
        trees[pair] = cKDTree(samples[pair])
    d, near = trees[pair].query(pts)
    ok = d <= REACH_RADII * job.tool.offset
    return [(pair, int(k)) if good else None for k, good in zip(near, ok)]
