"""Per-face deviations: every cutter centre against each face of the pair, by OCCT.

The path's contact parameters (u, w) only seed OCCT's local projection; a sample of cycles
(and each face's worst ones) is re-projected without seeds, and measured against the
trimmed face exactly, to prove the seeds did not steer the answer. Lengths in mm.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import InputError
from ..core.tolerances import Tolerances
from ..core.trim_labels import OUTSIDE
from ..geometry.part import load_step
from ..geometry.setup import setup_part
from .check_records import SurfaceCheck, cycle_ranges
from .probe import FaceProbe

PERCENTILES = (50, 95, 99)
SAMPLE_UNSEEDED = 64  # cycles per face re-projected without seeds (plus the worst ones)
TICK = 5000  # progress is reported every 5000 cycles


def resolve_part(toolpath, part):
    """``part``, or the part loaded from the STEP file the toolpath's job names, in the
    setup of the toolpath's job (its tool axis: :mod:`cadcnc.geometry.setup`)."""
    if part is not None:
        return setup_part(part, toolpath.job)
    source = toolpath.job.source
    if not source or str(source).startswith("<"):
        raise InputError("verify needs the part: the toolpath does not name a STEP file "
                         "(pass part=...)")
    return setup_part(load_step(source, flip_material=toolpath.job.flip_material),
                      toolpath.job)


def prepare(toolpath, part, tol: Tolerances, probe_of=None):
    """(part, probes): the part (see :func:`resolve_part`) and an OCCT probe for each face
    of the pair, by face number. InputError for an empty path or unnamed faces. A guide
    surface (offset 0, no face: a finishing pass on its plane) is not a face of the part
    and has no probe. ``probe_of(n)``: where the probes come from (default: new ones)."""
    if len(toolpath) == 0:
        raise InputError("verify: the toolpath has no points")
    part = resolve_part(toolpath, part)
    named = [n for n, o in zip(toolpath.faces, toolpath.offsets) if n is not None or o != 0]
    if None in named or not named:
        raise InputError("verify: the toolpath does not name its two faces")
    if probe_of is None:
        return part, {n: FaceProbe(part.face(n).topods, tol, part.face(n).box) for n in named}
    return part, {n: probe_of(n) for n in named}


def check_pair(toolpath, probes: dict[int, FaceProbe], tol: Tolerances, n_unseeded: int,
               progress=None, bounded: bool = False) -> list[SurfaceCheck]:
    """Both faces of the pair, each against its own offset (``bounded``: see
    :func:`check_surface`)."""
    out = []
    for side, n in enumerate(toolpath.faces):
        if n is None:  # a guide surface: the centres lie on it by construction
            continue
        if progress:
            progress(side, 2, "surfaces")
        tick = None
        if progress:
            def tick(k, n_points, side=side):
                progress(side * n_points + k, 2 * n_points, "surfaces")
        out.append(check_surface(probes[n], n, float(toolpath.offsets[side]),
                                 toolpath.points, toolpath.uv[:, side], n_unseeded, tol,
                                 tick, bounded))
    return out


def check_surface(probe: FaceProbe, face_no, offset: float, points: np.ndarray,
                  uw: np.ndarray, n_unseeded: int, tol: Tolerances,
                  tick=None, bounded: bool = False) -> SurfaceCheck:
    """Deviations of ``points`` (N, 3) from one face offset by ``offset``.

    ``uw`` (N, 2): the path's contact parameters on that face, used as seeds only.
    ``n_unseeded``: how many evenly spaced cycles are re-projected without seeds.
    ``tick(done, total)`` is called every :data:`TICK` points. ``bounded``: a sampled
    cycle skips the exact point-to-face distance (~16 ms on a B-spline face) where it
    cannot change the answer: its distance was measured exactly already (a foot outside
    the face), or bounds rule out a nearer point of the face (:func:`_nearer_ruled_out`);
    the answers are those of the full check (the reference gate's).
    """
    n = len(points)
    dist, signed, states, exact, feet = [], [], [], {}, []
    seeds = np.asarray(uw, float).tolist()  # floats: cheaper to OCCT than numpy's
    for k, p in enumerate(np.asarray(points, float).tolist()):
        if tick and k % TICK == 0:
            tick(k, n)
        res = probe.project_seeded(p, *seeds[k]) or probe.project_global(p)
        u, w, d = res
        feet.append((u, w))
        dist.append(d)
        signed.append(probe.signed(p, u, w, d))
        states.append(probe.state(u, w))
        if states[-1] == OUTSIDE:
            exact[k] = probe.face_distance(p)
    dist = np.array(dist, float)
    dev = np.array(signed, float) - offset
    fdev = dev.copy()
    for k, (sd, _) in exact.items():
        fdev[k] = sd - offset
    # do not trust the seeds: an unseeded global projection and an exact point-to-face
    # distance on a sample, plus the worst cycles
    sample = set(np.linspace(0, n - 1, min(n, n_unseeded)).astype(int).tolist())
    sample |= {int(np.argmin(fdev)), int(np.argmax(fdev)), int(np.argmin(dev))}
    gain, bad = 0.0, 0
    for k in sorted(sample):
        near = dist[k] if k in exact else max(dist[k], abs(fdev[k] + offset))
        if bounded and probe.surface_clear(points[k], *feet[k], near - 0.5 * tol.noise):
            # no point of the surface nearer than near - noise / 2: OCCT's global search
            # would find none nearer, so it could not decide (module doc)
            g = None
        else:
            g = probe.project_global(points[k])
        better = g is not None and g[2] < dist[k] - tol.noise
        if bounded and (k in exact or (g is None and _edges_clear(
                probe, points[k], abs(fdev[k] + offset), tol))
                        or _nearer_ruled_out(probe, points[k], g, abs(fdev[k] + offset),
                                             tol)):
            sd, ud = exact.get(k, (fdev[k] + offset, abs(fdev[k] + offset)))
        else:
            sd, ud = probe.face_distance(points[k])
        face_better = ud < abs(fdev[k] + offset) - tol.noise
        if better:
            gain = max(gain, dist[k] - g[2])
            dev[k] = probe.signed(points[k], *g) - offset
        if face_better:
            gain = max(gain, abs(fdev[k] + offset) - ud)
            fdev[k] = sd - offset
        bad += bool(better or face_better)
    over, under = np.maximum(-fdev, 0.0), np.maximum(fdev, 0.0)
    gap = np.abs(fdev + offset) - np.abs(dev + offset)
    return SurfaceCheck(
        face=face_no, offset=offset, deviation=dev, face_deviation=fdev, states=states,
        max_overcut_mm=float(over.max()), overcut_cycle=int(over.argmax()),
        max_undercut_mm=float(under.max()), undercut_cycle=int(under.argmax()),
        surface_max_overcut_mm=float(np.maximum(-dev, 0).max()),
        percentiles_mm={f"p{q}": float(np.percentile(np.abs(fdev), q)) for q in PERCENTILES},
        max_trim_gap_mm=float(gap.max()),
        off_face_cycles=cycle_ranges(np.nonzero(gap > tol.off_face)[0]),
        unseeded_checked=len(sample), unseeded_disagreements=bad,
        unseeded_max_gain_mm=float(gain))


def _edges_clear(probe: FaceProbe, point, d: float, tol: Tolerances) -> bool:
    """Whether the face's boundary lies at least ``d`` - noise / 2 from ``point`` (the
    second half of :func:`_nearer_ruled_out`, its first proven by the surface's bound)."""
    floor = d - 0.5 * tol.noise
    return probe.edge_gap(point, floor) >= floor


def _nearer_ruled_out(probe: FaceProbe, point, found, d: float, tol: Tolerances) -> bool:
    """Whether no point of the trimmed face lies nearer than ``d`` - noise / 2 to
    ``point``, whose seeded foot (at ``d``) lies on the face. A nearest point of the face
    is a critical point of the surface inside the face's parameter box, at least as far
    as OCCT's global search over that box found (``found``: its answer), or lies on the
    face's boundary, at least as far as OCCT's distance to its edges. Both bounds at d - noise / 2 or
    more: OCCT's exact distance could not undercut d by noise (the full check's test)."""
    floor = d - 0.5 * tol.noise
    return found is not None and found[2] >= floor and probe.edge_gap(point, floor) >= floor
