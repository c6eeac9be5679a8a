"""A computed toolpath: arrays per cycle plus the inputs and the reason it stopped.

Shapes (N = number of points, row 0 the start): points (N, 3) cutter centres in mm;
contacts (N, 2, 3) contact points on surface 1 and 2; normals (N, 2, 3); uv (N, 2, 2) the
contacts' native surface parameters; steps (N,) the length of the step that led to each
point (0 for the start), commanded (N,) the commanded step f = F Ts of that cycle (mm).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..interp.error_bounds import SurfaceBounds, bounds_for_surface, mp_length, surface_curvatures
from ..interp.stepper import PathRecord


@dataclass
class Toolpath:
    points: np.ndarray
    contacts: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    steps: np.ndarray
    commanded: np.ndarray
    offsets: tuple[float, float]
    stop_reason: str
    stop_detail: str = ""
    faces: tuple[int | None, int | None] = (None, None)
    inputs: dict = field(default_factory=dict)
    bounds: tuple[SurfaceBounds, SurfaceBounds] | None = None

    def __len__(self) -> int:
        return len(self.points)

    def __repr__(self) -> str:
        return (f"<Toolpath {len(self)} points, {self.length:.3f} mm, faces {self.faces}, "
                f"stop: {self.stop_reason}>")

    @property
    def length(self) -> float:
        """Polyline length through the cutter centres, mm."""
        return float(self.steps.sum())

    @property
    def duration(self) -> float:
        """Machining time in s: one interpolation period per cycle."""
        return (len(self) - 1) * float(self.inputs.get("period", float("nan")))

    @property
    def tangents(self) -> np.ndarray:
        """(N, 3) unit n1 x n2 at each point, signed along the direction of travel."""
        m = np.cross(self.normals[:, 0], self.normals[:, 1])
        m /= np.linalg.norm(m, axis=1)[:, None]
        if len(self) > 1:
            d = np.diff(self.points, axis=0)
            d = np.vstack([d, d[-1:]])
            m *= np.sign(np.einsum("ij,ij->i", m, d))[:, None] + (np.einsum(
                "ij,ij->i", m, d) == 0)[:, None]
        return m

    @property
    def worst_predicted_mm(self) -> float:
        """Largest steady-state error bound (eq. 16) over both surfaces, mm."""
        if self.bounds is None:
            return float("nan")
        vals = np.concatenate([b.eq16[:-1] if len(b.eq16) > 1 else b.eq16 for b in self.bounds])
        return float(vals.max()) if len(vals) else float("nan")


def toolpath_from_record(record: PathRecord, offsets: tuple[float, float], stop_reason: str,
                         stop_detail: str = "", faces=(None, None),
                         inputs: dict | None = None) -> Toolpath:
    """Arrays and the paper's error bounds from the stepper's per-cycle record."""
    rows = record.rows
    points = np.array([r[0] for r in rows], dtype=float)
    cs = [[r[1 + i] for r in rows] for i in (0, 1)]
    uv = np.array([[[c[0], c[1]] for c in side] for side in cs]).transpose(1, 0, 2)
    contacts = np.array([[c[2] for c in side] for side in cs]).transpose(1, 0, 2)
    normals = np.array([[c[5] for c in side] for side in cs]).transpose(1, 0, 2)
    path = Toolpath(
        points=points, contacts=contacts, normals=normals, uv=uv,
        steps=np.array([r[4] for r in rows], dtype=float),
        commanded=np.array([r[3] for r in rows], dtype=float),
        offsets=tuple(map(float, offsets)), stop_reason=stop_reason, stop_detail=stop_detail,
        faces=tuple(faces), inputs=dict(inputs or {}))
    path.bounds = compute_bounds(path, cs)
    return path


def compute_bounds(path: Toolpath, contact_rows) -> tuple[SurfaceBounds, SurfaceBounds]:
    """Per point, the bounds for the step leaving it (f = the next cycle's commanded step)."""
    t = path.tangents
    f = np.append(path.commanded[1:], path.commanded[-1] if len(path) > 1 else 0.0)
    curv = []
    for i, side in enumerate(contact_rows):
        ru = np.array([c[3] for c in side], dtype=float)
        rw = np.array([c[4] for c in side], dtype=float)
        ff = np.array([c[6:12] for c in side], dtype=float)
        curv.append(surface_curvatures(ru, rw, path.normals[:, i], ff, t))
    out = []
    for i in (0, 1):
        R = path.offsets[i]
        eps = np.linalg.norm(path.points - (path.contacts[:, i] + R * path.normals[:, i]), axis=1)
        k, kmax, kmin, tau = curv[i]
        mp = mp_length(R, curv[0][0], curv[1][0], path.contacts[:, 0], path.contacts[:, 1],
                       path.normals[:, 0], path.normals[:, 1])
        out.append(bounds_for_surface(R, f, eps, k, kmax, kmin, tau, mp))
    return out[0], out[1]
