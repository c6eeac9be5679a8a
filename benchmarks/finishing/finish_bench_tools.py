"""Measuring tools of the OpenCAMLib comparison (benchmarks/finishing/finish_vs_ocl.py).

- ``tessellate``: the selected faces as triangles by OCCT's BRepMesh_IncrementalMesh, as
  cq-cam feeds them to OpenCAMLib.
- ``run_ocl``: OpenCAMLib's BatchDropCutter on those triangles, in a subprocess
  (benchmarks/finishing/ocl_worker.py), returning ball centres (OCL's tool tip + R z).
- ``FaceDistances``: the true deviation of ball centres from the exact offset of the
  selected faces, by OCCT's own projection onto each face (seeded Newton, checked against
  BRepExtrema_DistShapeShape on a sample), and the rule "the ball lies wholly over a face":
  the centre's nearest point is inside its face, and the ball grown by ``margin`` does not
  reach that face's boundary edges (distance from the centre to the sampled boundary,
  less half the sampling step, at least R' + margin).

Units: mm and seconds. Signed deviation = distance - R': negative on the gouge side (the
centre nearer the face than R'), positive on the leave side.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.GCPnts import GCPnts_UniformAbscissa
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from scipy.spatial import cKDTree

from benchmarks import ROOT
from cadcnc.core.trim_labels import INSIDE
from cadcnc.geometry.mesh import face_triangles
from cadcnc.verification.probe import FaceProbe

ANGULAR = 0.1  # rad: cadquery's default angular tolerance of Shape.tessellate


def tessellate(faces, tolerance: float, angular: float = ANGULAR) -> tuple[np.ndarray, float]:
    """((T, 3, 3) triangles in mm, seconds of BRepMesh_IncrementalMesh) of copies of the
    TopoDS faces (the originals keep no mesh), linear deflection ``tolerance`` mm."""
    tris, seconds = [], 0.0
    for face in faces:
        copy = TopoDS.Face_s(BRepBuilderAPI_Copy(face).Shape())
        t0 = time.perf_counter()
        BRepMesh_IncrementalMesh(copy, tolerance, False, angular, False)
        seconds += time.perf_counter() - t0
        tris.append(face_triangles(copy))
    return np.concatenate(tris), seconds


@dataclass
class OclRun:
    centres: np.ndarray        # (N, 3) ball centres, mm (nan where no triangle lies under)
    seconds: dict              # "stl", "append", "run" (OCL's own), s
    threads: int


def run_ocl(triangles: np.ndarray, points: np.ndarray, radius: float, threads: int = 1,
            length: float = 50.0) -> OclRun:
    """BatchDropCutter of a ball of ``radius`` at the (N, 2) x, y ``points``, in a
    subprocess (opencamlib crashes beside cadquery's libraries)."""
    z0 = float(triangles[..., 2].min()) - radius - 10.0
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = os.path.join(tmp, "in.npz"), os.path.join(tmp, "out.npz")
        np.savez(src, triangles=triangles, points=points, radius=radius, length=length,
                 z0=z0, threads=threads)
        subprocess.run([sys.executable, "-m", "benchmarks.finishing.ocl_worker", src, dst],
                       cwd=ROOT,
                       check=True)
        out = np.load(dst)
        cl, seconds, used = out["cl"], out["seconds"], int(out["threads"])
    centres = cl + [0.0, 0.0, radius]
    centres[cl[:, 2] <= z0 + 1e-9] = np.nan  # nothing under the cutter: no location
    return OclRun(centres, dict(zip(("stl", "append", "run"), map(float, seconds))), used)


def boundary_samples(face, spacing: float) -> np.ndarray:
    """(M, 3) points along every edge of a TopoDS face, at most ``spacing`` mm apart."""
    out = []
    explorer = TopExp_Explorer(face, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        explorer.Next()
        if BRep_Tool.Degenerated_s(edge):
            continue
        curve = BRepAdaptor_Curve(edge)
        abscissa = GCPnts_UniformAbscissa(curve, spacing)
        if abscissa.IsDone() and abscissa.NbPoints() >= 2:
            params = [abscissa.Parameter(i) for i in range(1, abscissa.NbPoints() + 1)]
        else:  # shorter than the spacing
            params = [curve.FirstParameter(), curve.LastParameter()]
        params.append(curve.LastParameter())
        out.extend(curve.Value(t).Coord() for t in params)
    return np.array(out)


@dataclass
class Deviations:
    """Per ball centre: signed deviation from R' (mm), nearest face (index into the
    faces given), whether the ball lies wholly over that face, and the DSS cross-check."""

    signed: np.ndarray         # (N,) distance - R', mm (nan: not measured)
    face: np.ndarray           # (N,) int
    over: np.ndarray           # (N,) bool: counted in the comparison
    check_max: float           # max |Newton - DistShapeShape| over the checked sample, mm
    checked: int
    sizes: list                # points per polyline measured, in order

    def per_line(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """(signed, over) of each polyline."""
        cuts = np.cumsum([0, *self.sizes])
        return [(self.signed[a:b], self.over[a:b]) for a, b in zip(cuts[:-1], cuts[1:])]

    def summary(self) -> dict:
        """max |dev|, p50, p99 of |dev|, gouge side (most negative) and leave side (most
        positive) over the counted centres, mm; and the counts."""
        d = self.signed[self.over]
        a = np.abs(d)
        return dict(points=int(len(self.signed)), counted=int(len(d)),
                    max=float(a.max()), p50=float(np.percentile(a, 50)),
                    p99=float(np.percentile(a, 99)), gouge=float(min(d.min(), 0.0)),
                    leave=float(max(d.max(), 0.0)),
                    gouge_share=float(np.mean(d < 0)), check_max=float(self.check_max),
                    checked=self.checked)


class FaceDistances:
    """True distances from ball centres to the selected TopoDS faces (see module doc)."""

    def __init__(self, faces, offset: float, margin: float = 0.5, spacing: float = 0.02):
        self.probes = [FaceProbe(f) for f in faces]
        self.offset, self.margin, self.spacing = float(offset), float(margin), float(spacing)
        self.trees = [cKDTree(boundary_samples(f, spacing)) for f in faces]

    def _distance(self, k: int, p: np.ndarray, seed):
        """(distance, foot (u, w) or None, inside) from p to face k, seeded if possible."""
        probe = self.probes[k]
        found = probe.project_seeded(p, *seed) if seed is not None else None
        if found is None:
            found = probe.project_global(p)
        if found is not None and probe.state(found[0], found[1]) == INSIDE:
            return found[2], found[:2], True
        return probe.face_distance(p)[1], None, False  # nearest point on the boundary

    def polyline(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(signed (N,), face (N,), over (N,)) for consecutive centres of one pass
        (nan rows are skipped); each projection is seeded by the previous foot."""
        n = len(points)
        signed, face, over = np.full(n, np.nan), np.zeros(n, int), np.zeros(n, bool)
        seeds = [None] * len(self.probes)
        for i, p in enumerate(points):
            if not np.all(np.isfinite(p)):
                seeds = [None] * len(self.probes)
                continue
            best = (math.inf, -1, False)
            for k in range(len(self.probes)):
                d, foot, inside = self._distance(k, p, seeds[k])
                seeds[k] = foot
                if d < best[0]:
                    best = (d, k, inside)
            d, k, inside = best
            signed[i], face[i] = d - self.offset, k
            clear = self.trees[k].query(p)[0] - 0.5 * self.spacing
            over[i] = inside and clear >= self.offset + self.margin
        return signed, face, over

    def measure(self, polylines, check: int = 200, seed: int = 0) -> Deviations:
        """Deviations of every centre of ``polylines`` (a list of (N_k, 3)); ``check``
        counted centres are re-measured by BRepExtrema_DistShapeShape."""
        parts = [self.polyline(np.asarray(pl, float)) for pl in polylines]
        signed = np.concatenate([s for s, _, _ in parts])
        face = np.concatenate([f for _, f, _ in parts])
        over = np.concatenate([o for _, _, o in parts])
        points = np.concatenate([np.asarray(pl, float) for pl in polylines])
        rng = np.random.default_rng(seed)
        idx = np.flatnonzero(over)
        idx = rng.choice(idx, min(check, len(idx)), replace=False) if len(idx) else idx
        worst = 0.0
        for i in idx:
            d = min(pr.face_distance(points[i])[1] for pr in self.probes)
            worst = max(worst, abs(d - self.offset - signed[i]))
        return Deviations(signed, face, over, worst, int(len(idx)), [len(pl) for pl in polylines])
