"""The pencil operation's corners: every inner corner of a part a ball of offset R' cleans.

Two kinds (docs/pencil.md, "Corners found"):

- ``edge``: a concave, non-tangent shared edge of faces (i, j); ``edge`` is its index among
  that pair's concave edges (0-based, as ``PairPath.edge``).
- ``blend``: a concave blend (fillet, rolling-ball blend, or a chain of them) of radius
  r < R'. The ball cannot touch it and sits on the two faces (a, b) across its rails,
  which share no edge; ``seeds`` are ball centres (mm) touching a and b at the blend's
  ends, from which the stretch finder solves its tangencies.

Corners found and not to be cut carry ``skip`` (a reason key) and ``detail`` (a sentence):
``tangent`` faces, a ``mixed`` edge, a blend the ball rolls on (``blend_rolls``), a face
tighter than the ball or facing its partner (``no_fit``), a ``vertex_blend``, a blend
whose rails reach other than two faces (``blend_rails``), faces left out by ``faces=``
(``not_selected``), a concave edge shorter than the gouge limit (``degenerate``: a
sliver of the model, not a corner). Lengths mm.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ...core.errors import GeometryError
from ...core.job import Tool
from ...core.tolerances import DEFAULT, Tolerances
from ...geometry.blends import Blend, find_blends
from ...geometry.part import CONCAVE, MIXED, TANGENT, Part
from ...program.program import Skipped
from ..path.feasibility import too_tight

EDGE, BLEND = "edge", "blend"
TANGENT_FACES, MIXED_EDGE, BLEND_ROLLS = "tangent", "mixed", "blend_rolls"
NO_FIT, VERTEX_BLEND, BLEND_RAILS, NOT_SELECTED = ("no_fit", "vertex_blend", "blend_rails",
                                                   "not_selected")
DEGENERATE = "degenerate"  # a concave edge shorter than the gouge limit: nothing to cut
SAME_POINT = 1e-4  # mm: rail end points closer than this are one vertex
SEED_ITERATIONS = 4  # tangent-plane solves of a blend seed (curved faces a, b)
ROLLS = 1e-9      # relative: a blend of radius >= R' (1 - ROLLS) is one the ball rolls on


@dataclass(frozen=True)
class Corner:
    """One corner: kind, faces (a < b), its edge or blend faces, seeds, and a skip reason.

    ``seeds``: tuple of (3,) ball centres (mm) at the blend's ends (one for a closed blend,
    none for an edge corner); ``radius``: the blend's largest radius (mm); ``length``: the
    edge's or the rail's length (mm); ``skip`` None for a corner to cut; ``rails``: a
    blend corner's rail edges on face a (SharedEdge), where its stretches are anchored.
    """

    kind: str
    faces: tuple[int, int]
    edge: int | None = None
    blend_faces: tuple[int, ...] = ()
    seeds: tuple = ()
    radius: float | None = None
    length: float = 0.0
    closed: bool = False
    skip: str | None = None
    detail: str = ""
    rails: tuple = field(default=(), repr=False, compare=False)

    @property
    def cut(self) -> bool:
        return self.skip is None

    def sort_key(self) -> tuple:
        return (self.faces, self.kind, -1 if self.edge is None else self.edge,
                self.blend_faces, self.skip or "")

    def skipped(self) -> Skipped:
        """The program's record of this corner when it is skipped (edge 1-based)."""
        return Skipped(self.faces, self.skip or "", self.detail,
                       None if self.edge is None else self.edge + 1)


def _pair(i: int, j: int) -> tuple[int, int]:
    return (min(i, j), max(i, j))


def find_corners(part: Part, radius: float, allowance: float = 0.0,
                 faces=None, tol: Tolerances = DEFAULT) -> list[Corner]:
    """Every corner of ``part`` for a ball of radius R (mm) and allowance C (mm), in order.

    ``faces``: None for all faces, else an iterable of face numbers: corners whose two faces
    are not both in it are returned skipped (``not_selected``). ``tol.gouge``: concave
    edges shorter than it are skipped (``degenerate``).
    """
    rp = Tool(radius, allowance).offset
    blends, kranges = find_blends(part)
    # faces concave tighter than the ball at every sample: {face: least k_max, 1/mm}
    tight = {n: klo for n, (klo, _) in kranges.items() if too_tight(klo * rp, rp, DEFAULT)}
    corners = _blend_corners(part, blends, tight, rp)
    corners += _edge_corners(part, blends, tight, rp, tol.gouge)
    if faces is not None:
        keep = {int(n) for n in faces}
        for n in keep:
            part.face(n)  # FaceNumberError for a number out of range
        corners = [c if not c.cut or set(c.faces) <= keep else replace(
            c, skip=NOT_SELECTED, detail=f"faces {c.faces[0]} and {c.faces[1]}: not both "
            "among the faces asked for") for c in corners]
    return sorted(corners, key=Corner.sort_key)


def _edge_corners(part: Part, blends: dict[int, Blend], tight: dict[int, float],
                  rp: float, shortest: float) -> list[Corner]:
    """Concave edges (cut unless a face is tighter than the ball or the edge is shorter
    than ``shortest`` mm), mixed and tangent edges not belonging to a blend (skipped)."""
    owned = {id(e) for b in blends.values() for _, e in b.rails + b.ends}
    out = []
    for (i, j), edges in part.adjacency.items():
        concave = [e for e in edges if e.edge_class == CONCAVE]
        for k, e in enumerate(concave):
            c = Corner(EDGE, (i, j), edge=k, length=float(e.length), closed=e.closed)
            small = [n for n in (i, j) if n in tight]
            if not e.closed and not e.length >= shortest:
                c = replace(c, skip=DEGENERATE, detail=(
                    f"degenerate edge of {e.length:.3g} mm, shorter than the gouge limit "
                    f"{shortest:g} mm: a sliver of the model, not a corner"))
            elif small:
                r = 1.0 / tight[small[0]]
                c = replace(c, skip=NO_FIT, detail=(
                    f"face {small[0]} is concave tighter than the ball everywhere (radius "
                    f"<= {r:.4g} mm < R' {rp:.4g} mm): the ball cannot touch it"))
            out.append(c)
        for e in edges:
            lo, hi = e.angle_range_deg
            if e.edge_class == MIXED:
                out.append(Corner(EDGE, (i, j), length=float(e.length), skip=MIXED_EDGE,
                                  detail=f"edge both concave and convex (material angle "
                                  f"{lo:.1f}..{hi:.1f} deg)"))
            elif e.edge_class == TANGENT and id(e) not in owned:
                out.append(Corner(EDGE, (i, j), length=float(e.length), skip=TANGENT_FACES,
                                  detail=f"faces meet tangentially (material angle "
                                  f"{lo:.1f}..{hi:.1f} deg): no corner"))
    return out


def _outer(blends: dict[int, Blend], small: set[int], n: int, seen: set[int]) -> set[int]:
    """Faces reached across the rails of blend n, walking through the blends in ``small``
    (the blends of its own class: smaller than the ball, or not)."""
    seen.add(n)
    out: set[int] = set()
    for m, _ in blends[n].rails:
        if m in seen:
            continue
        if m in small and any(k == n for k, _ in blends[m].rails):
            out |= _outer(blends, small, m, seen)
        else:
            out.add(m)
    return out


def _blend_corners(part: Part, blends: dict[int, Blend], tight: dict[int, float],
                   rp: float) -> list[Corner]:
    """Concave blends: corners of the faces across them (r < R'), or skipped."""
    concave = {n: b for n, b in blends.items() if b.concave}
    rolls = rp * (1.0 - ROLLS)
    small = {n for n, b in concave.items() if b.r_max < rolls and not b.umbilic}
    out, pairs, rolled = [], {}, {}
    for n, b in concave.items():
        radius = f"blend radius {b.r_max:.4g} mm"
        if b.umbilic:
            reason = (BLEND_ROLLS, _rolls(b.r_max, rp)) if b.r_min >= rolls else (
                VERTEX_BLEND, f"vertex blend of radius {b.r_max:.4g} mm < R': the ball "
                "touches the faces around it, no corner of its own")
            out.append(_blend_record(b, tuple(sorted({m for m, _ in b.ends}))[:2], *reason))
            continue
        if n not in small:
            big = set(concave) - small
            rails = tuple(sorted(_outer(concave, big, n, set())))[:2]
            if rails:  # none: a hole's wall in pieces, closed on itself (not a corner)
                rolled[n] = _pair(*(rails + (n,) * (2 - len(rails))))
            continue
        outer = _outer(concave, small, n, set())
        if not outer:
            continue  # a hole's wall in pieces (its edges with a floor are edge corners)
        if len(outer) != 2:
            out.append(_blend_record(b, tuple(sorted(outer))[:2], BLEND_RAILS,
                                     f"{radius} < R' with rails reaching faces "
                                     f"{sorted(outer)}: not two faces, not handled"))
            continue
        pairs[n] = _pair(*outer)
    for group in _groups(concave, rolled):
        out.append(_rolled_record(concave, group, rolled[group[0]], rp, rolls))
    for group in _groups(concave, pairs):
        corner = _group_corner(part, concave, group, pairs[group[0]], rp)
        small_face = [n for n in corner.faces if n in tight]
        if small_face and corner.cut:
            corner = replace(corner, skip=NO_FIT, detail=(
                f"face {small_face[0]} across the blend is concave tighter than the ball "
                "everywhere: the ball cannot touch it"))
        out.append(corner)
    return out


def _rolls(r: float, rp: float) -> str:
    return f"blend radius {r:.4g} mm >= R' {rp:.4g} mm: the ball rolls on it, no pencil corner"


def _rolled_record(blends: dict[int, Blend], group: list[int], pair: tuple[int, int],
                   rp: float, rolls: float) -> Corner:
    """The skipped record of blend faces (one chain) not smaller than the ball."""
    lo = min(blends[n].r_min for n in group)
    hi = max(blends[n].r_max for n in group)
    if lo >= rolls:
        detail = _rolls(hi, rp)
    else:
        detail = (f"blend radius {lo:.4g}..{hi:.4g} mm straddles R' {rp:.4g} mm: not "
                  "handled as a corner")
    return Corner(BLEND, pair, blend_faces=tuple(group), radius=hi, skip=BLEND_ROLLS,
                  detail=detail)


def _blend_record(b: Blend, faces: tuple, reason: str, detail: str) -> Corner:
    faces = tuple(faces) + (b.face,) * (2 - len(faces))
    return Corner(BLEND, _pair(*faces), blend_faces=(b.face,), radius=b.r_max,
                  skip=reason, detail=detail)


def _groups(blends: dict[int, Blend], pairs: dict[int, tuple[int, int]]) -> list[list[int]]:
    """Small blend faces with the same pair (a, b), joined where they share an edge."""
    parent = {n: n for n in pairs}

    def root(n):
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    for n in pairs:
        for m, _ in blends[n].rails + blends[n].ends:
            if m in pairs and pairs[m] == pairs[n]:
                parent[root(m)] = root(n)
    groups: dict[int, list[int]] = {}
    for n in sorted(pairs):
        groups.setdefault(root(n), []).append(n)
    return list(groups.values())


def _free_ends(edges) -> list[np.ndarray]:
    """End points of a set of shared edges used once (the ends of the chain they form)."""
    ends = [p for e in edges if not e.closed for p in (e.start, e.end)]
    free = []
    for k, p in enumerate(ends):
        if sum(np.linalg.norm(p - q) < SAME_POINT for q in ends) == 1:
            free.append(p)
    return free


def _group_corner(part: Part, blends: dict[int, Blend], group: list[int],
                  pair: tuple[int, int], rp: float) -> Corner:
    """One blend corner of faces ``pair`` across the blend faces ``group``."""
    a, b = pair
    rails_a = [e for n in group for m, e in blends[n].rails if m == a]
    rails_b = [e for n in group for m, e in blends[n].rails if m == b]
    r = max(blends[n].r_max for n in group)
    corner = Corner(BLEND, pair, blend_faces=tuple(group), radius=r,
                    length=float(sum(e.length for e in rails_a)), rails=tuple(rails_a))
    ends_a = _free_ends(rails_a)
    closed = not ends_a
    if closed:
        ends_a = [rails_a[0].start]
    ends_b = [p for e in rails_b for p in (e.start, e.end)]
    seeds = []
    try:
        for pa in ends_a[:2]:
            pb = min(ends_b, key=lambda q: float(np.linalg.norm(q - pa)))
            seeds.append(_seed(part, a, pa, b, pb, rp))
    except (GeometryError, ValueError) as exc:
        return replace(corner, closed=closed, skip=NO_FIT, detail=(
            f"blend radius {r:.4g} mm < R' {rp:.4g} mm between faces {a} and {b}, but no "
            f"ball touches both at its ends: {exc}"))
    return replace(corner, seeds=tuple(seeds), closed=closed)


def _seed(part: Part, a: int, pa: np.ndarray, b: int, pb: np.ndarray,
          rp: float) -> np.ndarray:
    """Ball centre (3,) mm at distance R' from faces a and b, in the cross-section through
    pa (on a) and pb (on b): solved on the tangent planes at the contacts, which are then
    moved to the feet of the centre on each surface (SEED_ITERATIONS times; exact at once
    on planes)."""
    fa, fb = part.face(a), part.face(b)
    qa, qb = np.asarray(pa, float), np.asarray(pb, float)
    ua, ub = fa.project(qa)[:2], fb.project(qb)[:2]
    t = None
    x = None
    for _ in range(SEED_ITERATIONS):
        na, nb = fa.normal(*ua), fb.normal(*ub)
        qa, qb = fa.point(*ua), fb.point(*ub)
        if t is None:
            t = np.cross(na, nb)
            if np.linalg.norm(t) < part.tol.tangent_sin:
                raise ValueError(f"faces {a} and {b} are parallel across it (the ball does "
                                 "not fit)")
            t /= np.linalg.norm(t)
            mid = t @ (qa + qb) / 2
        new = np.linalg.solve(np.array([na, nb, t]), np.array([na @ qa + rp, nb @ qb + rp,
                                                               mid]))
        if x is not None and not np.linalg.norm(new - x) < rp:
            break  # the feet jumped (another branch of a surface): keep the last centre
        x = new
        try:  # feet of the centre on each surface (none on a cylinder's axis: keep x)
            ua = fa.project(x, within_face_box=False)[:2]
            ub = fb.project(x, within_face_box=False)[:2]
        except GeometryError:
            break
    return x
