"""How a finishing pass goes from one selected face to the next across their shared edge.

At the exit of face F through an edge shared with a selected face G (both at the edge
point q, the contact on the edge, the centre on the guide plane), the local dihedral
decides (``Tolerances.tangent_edge_deg``, material side as in
:mod:`cadcnc.geometry.part`):

- **tangent**: n_F = n_G at q: G's cut starts at F's last point, its contact at q;
- **convex**: the ball rolls over the edge. Its centre c = q(t) + R' m, m turning in the
  edge's normal plane from n_F to n_G (m(alpha) = slerp(n_F, n_G, alpha)), with the edge
  parameter t(alpha) solved (Brent) so that c stays on the plane: every point is exactly
  R' from the edge point nearest to it (c - q is normal to the edge), also where the
  edge crosses the plane obliquely. The arc is cut at the cycle step (angle R' theta / f
  steps) and ends where G's offset curve leaves the edge;
- **concave**: the ball touches both faces and the plane at the tri-tangent point
  (Newton on the four contact parameters, :func:`~cadcnc.interp.tangency.solve_tangency`
  with the centre held on the plane): F's cut ends there, G's starts there.

Lengths mm, angles rad unless named deg.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import brentq

from ...core.errors import StartPointError
from ...core.job import PairPath
from ...geometry.part import CONCAVE, CONVEX, TANGENT
from ...interp.cycle import END
from ...interp.stepper import Tangency
from ...interp.tangency import solve_tangency
from ...program.toolpath import Toolpath
from .check import along_pass
from .crossings import ROOT_XTOL, Crossing

__all__ = ["CONCAVE", "CONVEX", "TANGENT", "Transition", "transition"]


@dataclass
class Transition:
    """What happens at one exit: ``kind`` (None: the chain ends there), where the cut on
    the face ends (``end``), and the next face with its contact parameters there."""

    kind: str | None
    end: Tangency
    next_face: int | None = None
    next_uv: tuple[float, float] | None = None
    entry: Crossing | None = None
    roll: tuple | None = None   # convex: (pass, face, exit crossing, G's edge index)

    def arc(self, first) -> Toolpath:
        """The roll-over cut (convex), starting exactly at ``first`` (mm)."""
        return roll_arc(*self.roll, first)


def _edge_index(edges, edge) -> int | None:
    return next((k for k, e in enumerate(edges.edges) if e.same(edge)), None)


def transition(ps, face: int, exit_: Crossing) -> Transition:
    """The :class:`Transition` of pass ``ps`` (passes._Pass) at ``exit_`` of ``face``."""
    end = ps.tangency(exit_.point, exit_.uv)
    g = exit_.neighbour
    if g is None or g not in ps.setup.surfaces:
        return Transition(None, end)
    f_edges, g_edges = ps.setup.edges[face], ps.setup.edges[g]
    edge = f_edges.edges[exit_.edge_index]
    kg = _edge_index(g_edges, edge)
    if kg is None:
        return Transition(None, end)
    _, uv_g, n_g = g_edges.centre(g_edges.edges[kg], exit_.t)
    entries = [c for c in ps.crossings[g] if c.entry and not c.used and c.edge_index == kg]
    entry = min(entries, key=lambda c: abs(c.t - exit_.t), default=None)
    angle = math.degrees(math.acos(max(-1.0, min(1.0, float(exit_.normal @ n_g)))))
    if angle <= ps.job.tolerances.tangent_edge_deg:
        return Transition(TANGENT, end, g, uv_g, entry)
    inward_g = g_edges.edges[kg].inward(exit_.t)
    if inward_g @ exit_.normal > 0.0:   # G rises on F's side: a concave edge
        offs = (ps.job.tool.offset, ps.job.tool.offset)
        try:
            tri = solve_tangency(ps.setup.surfaces[face], ps.setup.surfaces[g], offs,
                                 exit_.uv, uv_g, exit_.point, direction=ps.nrm,
                                 tol=ps.job.tolerances, what="tri-tangent point")
        except StartPointError:
            return Transition(None, end)
        if not (ps.setup.surfaces[face].contains(*tri.uv1)
                and ps.setup.surfaces[g].contains(*tri.uv2)):
            return Transition(None, end)
        return Transition(CONCAVE, ps.tangency(tri.p, tri.uv1), g, tri.uv2,
                          _entry_before(ps.crossings[g], np.asarray(tri.p), ps.travel))
    if entry is None:
        return Transition(None, end)
    return Transition(CONVEX, end, g, entry.uv, entry, roll=(ps, face, exit_, kg, entry))


def _entry_before(crossings, p: np.ndarray, travel: np.ndarray) -> Crossing | None:
    """The entry of the piece of a face's curve that contains the centre ``p`` (the last
    of its crossings before p in their order along the pass, :func:`.check.along_pass`,
    when that is an unused entry): a concave transition starts the next face inside
    that piece, past its entry (which lies in the shadow of the face left, on whichever
    edge of it; on a wall climbed, below p)."""
    here = Crossing(-1, -1, 0.0, (0.0, 0.0), p, np.zeros(3), float(p @ travel), False, None)
    order = along_pass(list(crossings) + [here], travel)
    k = next(i for i, c in enumerate(order) if c is here)
    last = order[k - 1] if k > 0 else None
    return last if last is not None and last.entry and not last.used else None


def _slerp(a: np.ndarray, b: np.ndarray, alpha: float) -> np.ndarray:
    """The unit vector at fraction ``alpha`` of the great arc from a to b."""
    theta = math.acos(max(-1.0, min(1.0, float(a @ b))))
    if theta < 1e-12:   # rad: a == b to round-off (sin theta -> 0)
        return a
    return (math.sin((1.0 - alpha) * theta) * a + math.sin(alpha * theta) * b) / math.sin(theta)


def roll_arc(ps, face: int, exit_: Crossing, kg: int, entry: Crossing, first) -> Toolpath:
    """The centres of the ball rolling over the convex edge of ``exit_`` from face
    ``face`` to the neighbour (its edge index ``kg``) in the pass's plane, from
    ``first`` (F's last point) to G's ``entry``: points (N, 3) about one cycle step
    apart, each R' from the edge point q(t) nearest to it (see the module doc)."""
    f_edges, g_edges = ps.setup.edges[face], ps.setup.edges[entry.face]
    cf, cg = f_edges.edges[exit_.edge_index], g_edges.edges[kg]
    rp, nrm, off = ps.job.tool.offset, ps.nrm, ps.plane.offset
    theta = math.acos(max(-1.0, min(1.0, float(exit_.normal @ entry.normal))))
    n = max(1, int(math.ceil(rp * theta / ps.job.step)))
    span = abs(cf.t1 - cf.t0)

    def at(t: float, alpha: float):
        c_f, uv, n_f = f_edges.centre(cf, t)
        q = c_f - rp * n_f
        m = _slerp(n_f, g_edges.centre(cg, t)[2], alpha)
        return q + rp * m, q, uv, m

    for _ in range(4):   # an edge crossing the plane obliquely makes the arc longer
        points, contacts, uvs, normals = _arc_points(at, n, exit_.t, entry.t, nrm, off, span)
        longest = float(np.linalg.norm(np.diff(points, axis=0), axis=1).max())
        if longest <= ps.job.step * (1.0 + 1e-6):   # relative round-off
            break
        n = int(math.ceil(n * longest / ps.job.step))
    points[0] = np.asarray(first, float)
    points[-1] = entry.point
    pts = np.array(points)
    steps = np.r_[0.0, np.linalg.norm(np.diff(pts, axis=0), axis=1)]
    guide_uv = np.array([ps.tangency(p, (0.0, 0.0)).uv2 for p in pts])
    job = ps.job
    op = PairPath(faces=(face, None), offsets=(None, 0.0), start=tuple(pts[0]), edge=None)
    return Toolpath(
        points=pts, contacts=np.stack([np.array(contacts), pts], axis=1),
        normals=np.stack([np.array(normals), np.tile(nrm, (len(pts), 1))], axis=1),
        uv=np.stack([np.array(uvs), guide_uv], axis=1), steps=steps,
        commanded=np.r_[0.0, np.full(len(pts) - 1, job.step)],
        job=replace(job, operation=op), stop_reason=END,
        stop_detail=f"rolled over the convex edge of faces {face} and {entry.face}")


def _arc_points(at, n: int, t_first: float, t_last: float, nrm, off: float, span: float):
    """n + 1 arc points at alpha = k / n: (centres, edge points, uv, normals), lists."""
    points, contacts, uvs, normals = [], [], [], []
    t_prev = t_first
    for k in range(n + 1):
        alpha = k / n
        if k == 0:
            t = t_first
        elif k == n:
            t = t_last
        else:
            t = _root(lambda x: float(at(x, alpha)[0] @ nrm - off), t_prev, t_last,
                      abs(t_last - t_prev) / (n - k + 1), span)
        c, q, uv, m = at(t, alpha)
        points.append(c)
        contacts.append(q)
        uvs.append(uv)
        normals.append(m)
        t_prev = t
    return points, contacts, uvs, normals


def _root(h, t0: float, t1: float, step: float, span: float) -> float:
    """The root of h nearest the edge parameter t0 (the arc's previous point): brackets
    from t0 to t0 +- pad, the side towards t1 first, pad from ``step`` doubling. Not a
    bracket round t0 and t1: where the plane runs near the edge's tangent (an edge circle
    just inside the plane's offset) h is positive only between two roots, on both sides
    of the arc's, and a wide bracket holding both never changes sign."""
    h0 = h(t0)
    if h0 == 0.0:
        return t0
    toward = 1.0 if t1 >= t0 else -1.0
    pad = max(step, 1e-9 * max(span, 1.0))   # > 0: the bracket grows
    for _ in range(60):
        for b in (t0 + toward * pad, t0 - toward * pad):
            hb = h(b)
            if hb == 0.0 or math.copysign(1.0, hb) != math.copysign(1.0, h0):
                return brentq(h, min(t0, b), max(t0, b), xtol=ROOT_XTOL,
                              rtol=4 * np.finfo(float).eps)
        pad *= 2.0
    raise StartPointError("roll-over arc: no point of the arc found on the guide plane")
