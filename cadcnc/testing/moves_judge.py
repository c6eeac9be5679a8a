"""An independent judge of written moves: OCCT's distance from points to a part's faces
and OCCT's solid classifier give the ball's depth into the part (no cadcnc geometry)."""

from __future__ import annotations

import math

import numpy as np
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt
from OCP.TopAbs import TopAbs_IN
from OCP.TopoDS import TopoDS_Compound

from cadcnc.io.gcode import programmed_moves


def boundary_distances(part, points: np.ndarray) -> np.ndarray:
    """(N,) distance (mm) from each point to the part's boundary: OCCT's vertex-to-shape
    distance to the compound of all its faces, i.e. the least vertex-to-face distance over
    its faces (one call per point: OCCT skips the faces whose boxes are farther)."""
    faces = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(faces)
    for n in range(1, len(part) + 1):
        builder.Add(faces, part.face(n).topods)
    dss = BRepExtrema_DistShapeShape()
    dss.LoadS2(faces)
    out = np.empty(len(points))
    for k, p in enumerate(points):
        dss.LoadS1(BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex())
        dss.Perform()
        assert dss.IsDone()
        out[k] = dss.Value()
    return out


def polyline_depths(part, points: np.ndarray, ball: float) -> np.ndarray:
    """(N,) depth R' -/+ d (mm) of the ball at each point of a polyline: R' - d outside
    the solid, R' + d inside. Membership comes from OCCT's solid classifier, asked again
    only where two consecutive points' boundary-free balls (radius d) do not cover the
    segment between them (then the segment might cross the boundary)."""
    d = boundary_distances(part, points)
    classifier = BRepClass3d_SolidClassifier(part.shape)
    inside = np.empty(len(points), bool)
    for k, p in enumerate(points):
        if k and d[k - 1] + d[k] >= np.linalg.norm(p - points[k - 1]):
            inside[k] = inside[k - 1]
            continue
        classifier.Perform(gp_Pnt(*map(float, p)), 1e-9)   # mm: on the boundary
        inside[k] = classifier.State() == TopAbs_IN
    return np.where(inside, ball + d, ball - d)


def move_samples(moves: np.ndarray, spacing: float) -> np.ndarray:
    """(K, 3) points along the polyline ``moves``: its vertices and samples at most
    ``spacing`` mm apart on every move."""
    out = [moves[:1]]
    for a, b in zip(moves[:-1], moves[1:]):
        n = max(1, int(math.ceil(np.linalg.norm(b - a) / spacing)))
        t = np.linspace(0.0, 1.0, n + 1)[1:, None]
        out.append(a + t * (b - a))
    return np.vstack(out)


def deepest(part, ngc: str, ball: float) -> float:
    """The ball's deepest reach (mm) into the part along a G-code program's moves (ball
    centres programmed), sampled at most min(1, max(0.05, R'/2)) mm apart."""
    moves = programmed_moves(ngc)
    spacing = min(1.0, max(0.05, ball / 2))
    return float(polyline_depths(part, move_samples(moves, spacing), ball).max())
