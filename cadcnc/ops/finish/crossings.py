"""Where a guide plane's offset curve crosses the boundary of a selected face.

The ball of offset R' touching face F with its centre on the plane ``dot(p, nrm) = off``
has its contact on the curve g(u, w) = (r + R' n) . nrm - off = 0 of F's surface. That
curve enters or leaves the trimmed face where it crosses one of F's boundary edges: a
root of g along the edge (contact on the edge, centre r + R' n_F there).

Roots are found robustly (:class:`FaceEdges`): each edge is sampled once per face and
offset, at most ``SAMPLE_MM`` apart and so densely that the centre's path along the edge
turns by at most ``TURN_DEG`` between samples (a curved edge gets more samples), with the
derivative of the centre along the edge at each sample. Per plane, g and its derivative
g' follow from these by dot products. A sign change of g brackets a root (Brent's method
on the exact edge, to 1e-13 of its parameter); an interval whose ends have the same sign
but whose g' changes sign towards zero may hide two close roots (a plane grazing the edge
or passing near a vertex): its extremum is solved (Brent on g'), and where g changes sign
there, both roots are solved on either side. An extremum touching zero within
``GRAZE_MM`` is a tangency (the plane grazes the edge): no crossing, the section only
touches the boundary there. An exact zero of g counts as positive, so
a plane through a vertex crosses one of its edges there, or both (a corner piece of no
length).

**Orientation.** The pass's centre moves along the plane's offset curve with the
material on its right seen along -nrm for forward travel (left for reverse): its tangent
is :func:`pass_tangent`, (n . z) travel - (n . travel) z normalised, defined by the
normal alone (also where the curve is vertical: the bottom of a round, a wall climbed),
and equal to the travel-signed tangent wherever n_z > 0. A crossing is an *entry* when
the contact, moving with the centre along that tangent, moves into the face. Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from ...geometry.face_edges import BoundaryEdge, boundary_edges
from ...geometry.face_surface import FaceSurface
from ...interp.cycle import Contact, inverse_exact
from ...interp.vec3 import add, cross, dot, norm

SAMPLE_MM = 0.25
"""Largest edge sample spacing (mm)."""
TURN_DEG = 10.0
"""deg: the centre's path along an edge turns at most this much between two samples, so
that g' changes sign at most once between them (one hidden extremum, solved)."""
GRAZE_MM = 1e-9
"""mm: an extremum of g this near zero is a tangency of the plane and the edge's centre
path (a graze): the section touches the face's boundary there without crossing it."""
ROOT_XTOL = 1e-13   # brentq's absolute tolerance on an edge parameter: round-off
Z = np.array([0.0, 0.0, 1.0])


def pass_tangent(n: np.ndarray, travel: np.ndarray) -> np.ndarray:
    """(3,) unit tangent of the centre's curve in the plane spanned by ``travel`` (unit,
    horizontal, the pass direction times the travel sense) and Z, at a contact of outward
    normal ``n`` (3,): (n_z travel - (n . travel) z) normalised (module doc). Raises
    ValueError where n is normal to that plane (a wall parallel to the guide plane)."""
    t = n[2] * travel - float(n @ travel) * Z
    length = float(np.linalg.norm(t))
    if length < 1e-12:   # no direction (n parallel to Z x travel)
        raise ValueError("the face is parallel to the guide plane here")
    return t / length


@dataclass
class Crossing:
    """The contact on a boundary edge of ``face`` with the centre on the plane.

    ``t`` edge parameter; ``uv`` contact parameters on the face; ``point`` (3,) centre;
    ``s`` = point . travel direction (mm, signed by the travel sense); ``entry``: the
    contact moves into the face along the travel; ``neighbour``: the other face on the
    edge (None for a free edge). ``used``: consumed by a chain."""

    face: int
    edge_index: int
    t: float
    uv: tuple[float, float]
    point: np.ndarray
    normal: np.ndarray
    s: float
    entry: bool
    neighbour: int | None
    used: bool = field(default=False, compare=False)


class FaceEdges:
    """One face's boundary edges, oriented in the face, sampled for an offset R' (mm)."""

    def __init__(self, part, face: FaceSurface, offset: float):
        self.face = face
        self.offset = offset
        self.edges: list[BoundaryEdge] = boundary_edges(part, face)
        self.neighbours = [e.neighbour for e in self.edges]
        self.samples = [self._sample(e) for e in self.edges]

    def centre(self, edge: BoundaryEdge, t: float
               ) -> tuple[np.ndarray, tuple[float, float], np.ndarray]:
        """(r + R' n (3,), (u, w), n (3,)) with the contact at edge parameter t."""
        u, w = edge.uv(t)
        r, ru, rw = self.face.derivative_tuples(u, w)[:3]
        c = cross(ru, rw)
        length = norm(c)
        if length <= self.face.tol.singular * (dot(ru, ru) + dot(rw, rw)):
            n = self.face.normal(u, w)   # a pole: names the point (SingularPointError)
        else:
            n = np.array(c) * (self.face.normal_sign / length)
        return np.array(r) + self.offset * n, (u, w), n

    def velocity(self, curve: BoundaryEdge, t: float) -> np.ndarray:
        """(3,) d(centre)/dt at edge parameter t (central difference inside the edge)."""
        t0, t1 = curve.t0, curve.t1
        h = 1e-6 * (t1 - t0)   # finite-difference step, relative to the edge's range
        a, b = max(t0, t - h), min(t1, t + h)
        return (self.centre(curve, b)[0] - self.centre(curve, a)[0]) / (b - a)

    def _sample(self, curve: BoundaryEdge):
        """(ts (K,), centres (K, 3), velocities (K, 3)): at most SAMPLE_MM apart, and
        refined uniformly until the centre's path turns at most TURN_DEG per interval."""
        t0, t1 = curve.t0, curve.t1
        count = max(9, int(math.ceil(curve.length / SAMPLE_MM)) + 1)
        for _ in range(4):
            ts = np.linspace(t0, t1, count)
            centres = np.array([self.centre(curve, t)[0] for t in ts])
            vel = np.array([self.velocity(curve, t) for t in ts])
            unit = vel / np.maximum(np.linalg.norm(vel, axis=1), 1e-300)[:, None]  # no / 0
            cos = np.clip(np.einsum("ij,ij->i", unit[:-1], unit[1:]), -1.0, 1.0)
            turn = math.degrees(float(np.arccos(cos).max()))
            if turn <= TURN_DEG:
                break
            count = (count - 1) * int(math.ceil(turn / TURN_DEG)) + 1
        return ts, centres, vel

    def crossings(self, nrm: np.ndarray, off: float, travel: np.ndarray,
                  tangent=None) -> list[Crossing]:
        """Every crossing of the plane dot(p, nrm) = off by this face's offset contact
        curve (module doc: close roots and grazes included), classified for a centre
        moving along ``travel`` (the pass direction (3,) times the travel sense), or
        along ``tangent(n)`` (the curve's unit tangent at a contact of normal n, ValueError
        where it has none) when given (a horizontal plane's loops)."""
        out: list[Crossing] = []
        for k, (curve, (ts, centres, vel)) in enumerate(zip(self.edges, self.samples)):
            for t in self._roots(curve, ts, centres @ nrm - off, vel @ nrm, nrm, off):
                c, uv, n = self.centre(curve, t)
                try:
                    entry = self._enters(k, t, uv, n, nrm, travel, tangent)
                except ValueError:
                    continue   # parallel to the plane there: no pass crosses it
                if any(o.entry == entry
                       and np.linalg.norm(o.point - c) <= 1e-9   # mm: already found
                       for o in out):
                    continue   # one point found twice (a closed edge's vertex)
                out.append(Crossing(self.face.number, k, t, uv, c, n, float(c @ travel),
                                    entry, self.neighbours[k]))
        return out

    def _roots(self, curve, ts, g, dg, nrm, off) -> list[float]:
        """Edge parameters where g = centre . nrm - off vanishes (module doc), ascending;
        g (K,) and its derivative dg (K,) at the samples ts (K,)."""
        def h(x: float) -> float:
            return float(self.centre(curve, x)[0] @ nrm - off)

        def dh(x: float) -> float:
            return float(self.velocity(curve, x) @ nrm)

        def solve(a: float, b: float) -> float:
            ha, hb = h(a), h(b)
            if np.signbit(ha) == np.signbit(hb):   # a closed edge's vertex, by rounding
                return a if abs(ha) <= abs(hb) else b
            return brentq(h, a, b, xtol=ROOT_XTOL, rtol=4 * np.finfo(float).eps)

        g = np.array(g, float)
        if float(np.linalg.norm(self.centre(curve, ts[0])[0] - self.centre(curve, ts[-1])[0])
                 ) <= ROOT_XTOL * max(1.0, abs(curve.t1 - curve.t0)):
            g[-1] = g[0]   # a closed edge: its vertex is one point, with one sign
        neg = np.signbit(g)   # an exact zero counts as positive (the plane a hair lower)
        roots = []
        for i in range(len(ts) - 1):
            a, b = float(ts[i]), float(ts[i + 1])
            if neg[i] != neg[i + 1]:
                roots.append(solve(a, b))
                continue
            # same sign: an extremum towards zero inside may hide two roots (a graze)
            if not (dg[i] * dg[i + 1] < 0.0 and (dg[i] < 0.0) != neg[i]):
                continue
            m = brentq(dh, a, b, xtol=ROOT_XTOL)
            gm = h(m)
            if bool(np.signbit(gm)) != neg[i] and abs(gm) > GRAZE_MM:
                roots += [solve(a, m), solve(m, b)]
        return sorted(roots)

    def _enters(self, k: int, t: float, uv, n: np.ndarray, nrm: np.ndarray,
                travel: np.ndarray, tangent=None) -> bool:
        """Whether the contact moves into the face when the centre moves along the
        plane's curve in the travel sense (:func:`pass_tangent`): the contact's move
        through the whole shape operator (the interpolator's exact inverse), against the
        face's inward direction."""
        tau = pass_tangent(n, travel) if tangent is None else tangent(n)
        contact = Contact(self.face, self.offset, *uv)
        du, dw = inverse_exact(contact, add(contact.centre(), tuple(map(float, tau))))
        move = du * np.array(contact.ru) + dw * np.array(contact.rw)
        inward = self.edges[k].inward(t)
        return bool(move @ inward > 0.0)
