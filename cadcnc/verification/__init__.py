"""Independent ground truth: check a toolpath against OpenCASCADE (issue 4).

:func:`verify` measures a :class:`~cadcnc.toolpath.Toolpath` with OCCT's own algorithms,
never with the interpolator's arithmetic: the path's contact parameters are used only to
seed projections, and a sample is re-projected without seeds to prove the seeds did not
steer the answer. Sign convention: a surface's deviation is the signed distance of the
cutter centre from it (+ out of the material) minus its offset R' = R + C, so a negative
deviation is an over-cut (the ball cuts into the face, a gouge) and a positive one an
under-cut (material left). Lengths in mm, times in s. See docs/validation.md.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from . import probe as occt
from ..errors import InputError
from .reference import ReferenceCheck, check_reference

NOISE_MM = 1e-8  # below this is round-off: start tangency solved to 1e-9, IntSS curve ~5e-9


@dataclass
class SurfaceCheck:
    """One face of the pair: deviations per cycle (N,) and their summary, mm.

    ``deviation``: against the untrimmed surface; ``face_deviation``: against the
    trimmed face (its nearest point, boundary included); ``trim_gap`` the difference
    (> 0 where the nearest surface point lies outside the face: the ball touches only
    the surface's extension there). ``unseeded_*``: the global re-projection check.
    """

    face: int | None
    offset: float
    deviation: np.ndarray = field(repr=False)
    face_deviation: np.ndarray = field(repr=False)
    states: list = field(repr=False)
    max_overcut_mm: float = 0.0
    overcut_cycle: int = -1
    max_undercut_mm: float = 0.0
    undercut_cycle: int = -1
    surface_max_overcut_mm: float = 0.0
    percentiles_mm: dict = field(default_factory=dict)
    max_trim_gap_mm: float = 0.0
    off_face_cycles: list = field(default_factory=list)
    unseeded_checked: int = 0
    unseeded_disagreements: int = 0
    unseeded_max_gain_mm: float = 0.0


@dataclass
class VerificationReport:
    """Everything :func:`verify` measured; ``to_dict()`` for JSON, ``format_table()`` for people."""

    faces: tuple
    n_points: int
    radius: float
    ball_radius: float
    offsets: tuple
    stop_reason: str
    stop_detail: str
    surfaces: list
    reference: ReferenceCheck
    feed: dict
    theory: list
    whole_part: dict
    stop: dict
    edge_deviation_mm: float | None = None
    seconds: dict = field(default_factory=dict)

    @property
    def max_overcut_mm(self) -> float:
        return max(s.max_overcut_mm for s in self.surfaces)

    @property
    def max_undercut_mm(self) -> float:
        return max(s.max_undercut_mm for s in self.surfaces)

    @property
    def hausdorff_mm(self) -> float:
        return self.reference.hausdorff_mm

    @property
    def coverage(self) -> float:
        return self.reference.coverage

    @property
    def whole_part_hits(self) -> list:
        return self.whole_part["hits"]

    @property
    def max_gouge_mm(self) -> float:
        """Deepest cut of the ball into any face of the part (the pair's included), mm."""
        depths = [h["depth_mm"] for h in self.whole_part_hits]
        return float(max([self.max_overcut_mm, *depths]))

    def ok(self, tolerance_mm: float = 1e-3) -> bool:
        """True when no face of the part is gouged deeper than ``tolerance_mm``."""
        return self.max_gouge_mm <= tolerance_mm

    def to_dict(self) -> dict:
        """JSON-ready summary (no per-cycle arrays)."""
        surfaces = []
        for s in self.surfaces:
            d = {k: v for k, v in asdict(s).items()
                 if k not in ("deviation", "face_deviation", "states")}
            surfaces.append(d)
        ref = {k: v for k, v in asdict(self.reference).items() if k != "points_to_branch"}
        return _jsonable(dict(
            max_overcut_mm=self.max_overcut_mm, max_undercut_mm=self.max_undercut_mm,
            hausdorff_mm=self.hausdorff_mm, coverage=self.coverage,
            whole_part_hits=self.whole_part_hits, max_gouge_mm=self.max_gouge_mm,
            faces=list(self.faces), n_points=self.n_points, radius=self.radius,
            ball_radius=self.ball_radius, offsets=list(self.offsets),
            stop_reason=self.stop_reason, stop_detail=self.stop_detail, stop=self.stop,
            surfaces=surfaces, reference=ref, feed=self.feed, theory=self.theory,
            whole_part={k: v for k, v in self.whole_part.items() if k != "hits"},
            edge_deviation_mm=self.edge_deviation_mm, seconds=self.seconds))

    def format_table(self, tolerance_mm: float = 1e-3) -> str:
        from .table import format_table

        return format_table(self, tolerance_mm)


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def _ranges(cycles) -> list:
    """[a, b] runs of consecutive cycle numbers."""
    out = []
    for c in map(int, cycles):
        if out and c == out[-1][1] + 1:
            out[-1][1] = c
        else:
            out.append([c, c])
    return out


def _resolve_part(toolpath, part):
    if part is not None:
        return part
    from ..geometry.part import load_step

    source = toolpath.inputs.get("source")
    if not source or str(source).startswith("<"):
        raise InputError("verify needs the part: the toolpath does not name a STEP file "
                         "(pass part=...)")
    return load_step(source)


def _check_surface(probe, face_no, offset, points, uv, n_unseeded) -> SurfaceCheck:
    n = len(points)
    dev, fdev, states, dist = (np.empty(n), np.empty(n), [], np.empty(n))
    feet = np.empty((n, 2))
    for k, p in enumerate(points):
        res = probe.project_seeded(p, *uv[k])
        if res is None:
            res = probe.project_global(p)
        u, v, d = res
        feet[k] = u, v
        dist[k] = d
        dev[k] = probe.signed(p, u, v, d) - offset
        states.append(probe.state(u, v))
        fdev[k] = dev[k] if states[-1] != occt.OUT else probe.face_distance(p)[0] - offset
    # do not trust the seeds: an unseeded global projection and an exact point-to-face
    # distance on a sample, plus the worst cycles
    sample = set(np.linspace(0, n - 1, min(n, n_unseeded)).astype(int).tolist())
    sample |= {int(np.argmin(fdev)), int(np.argmax(fdev)), int(np.argmin(dev))}
    gain, bad = 0.0, 0
    for k in sorted(sample):
        g = probe.project_global(points[k])
        better = g is not None and g[2] < dist[k] - NOISE_MM
        sd, ud = probe.face_distance(points[k])
        face_better = ud < abs(fdev[k] + offset) - NOISE_MM
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
        percentiles_mm={f"p{q}": float(np.percentile(np.abs(fdev), q)) for q in (50, 95, 99)},
        max_trim_gap_mm=float(gap.max()), off_face_cycles=_ranges(np.nonzero(gap > 1e-6)[0]),
        unseeded_checked=len(sample), unseeded_disagreements=bad,
        unseeded_max_gain_mm=float(gain))


def _check_feed(toolpath) -> dict:
    pts = toolpath.points
    if len(pts) < 2:
        return dict(max_rel_error=0.0, worst_cycle=-1, excluded_last=False)
    measured = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    commanded = np.asarray(toolpath.commanded[1:], float)
    rel = np.abs(measured - commanded) / commanded
    excluded = bool(toolpath.stop_reason in ("end", "closed", "boundary")
                    and measured[-1] < commanded[-1])
    body = rel[:-1] if excluded else rel
    worst = int(np.argmax(body)) + 1 if len(body) else -1
    period = float(toolpath.inputs.get("period", math.nan))
    return dict(
        max_rel_error=float(body.max()) if len(body) else 0.0, worst_cycle=worst,
        worst_step_mm=float(measured[worst - 1]) if worst > 0 else math.nan,
        worst_commanded_mm=float(commanded[worst - 1]) if worst > 0 else math.nan,
        excluded_last=excluded, last_step_mm=float(measured[-1]),
        recorded_vs_measured_mm=float(np.abs(measured - toolpath.steps[1:]).max()),
        commanded_min_mm=float(commanded.min()), commanded_max_mm=float(commanded.max()),
        feed_profile=bool(commanded.max() - commanded.min() > 1e-12),
        feed_min_mm_min=float(commanded.min() / period * 60.0),
        feed_max_mm_min=float(commanded.max() / period * 60.0))


def _theory(toolpath, surfaces) -> list:
    """Measured per-cycle deviation of point k+1 against the bounds of the step leaving k."""
    out = []
    for side, s in enumerate(surfaces):
        b = None if toolpath.bounds is None else toolpath.bounds[side]
        over = np.maximum(-s.deviation[1:], 0.0)
        absdev = np.abs(s.deviation[1:])
        row = dict(face=s.face, measured_overcut_mm=float(over.max(initial=0.0)),
                   measured_abs_mm=float(absdev.max(initial=0.0)))
        if b is not None and len(over):
            for name in ("eq11", "eq12", "eq16"):
                bound = np.asarray(getattr(b, name), float)[:-1]
                row[f"{name}_max_mm"] = float(np.nanmax(bound))
                row[f"{name}_exceeded_overcut"] = int((over > bound + NOISE_MM).sum())
                row[f"{name}_exceeded_abs"] = int((absdev > bound + NOISE_MM).sum())
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = np.where(absdev > NOISE_MM, absdev / b.eq16[:-1], 0.0)
            row["worst_ratio_to_eq16"] = float(np.nanmax(ratio))
            row["worst_ratio_cycle"] = int(np.nanargmax(ratio)) + 1
        out.append(row)
    return out


def _whole_part(part, probes, toolpath, surfaces, ball, hit_tol, progress) -> dict:
    """The ball at every centre against every face: bbox prefilter + exact OCCT distance.

    A face whose optimal bounding box, grown by the ball radius, misses a centre cannot
    touch the ball there. Otherwise the exact point-to-face distance d is computed; as d
    is 1-Lipschitz along the path, the next d - ball - hit_tol mm of path travel cannot
    hit that face and is skipped without loss.
    """
    pts = toolpath.points
    travel = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    hits, evaluated = [], 0
    pair = {s.face: s for s in surfaces}
    for n in range(1, len(part) + 1):
        if progress:
            progress("whole part", n, len(part))
        if n in pair:
            s = pair[n]
            depth = ball - (s.face_deviation + s.offset)
            evaluated += len(pts)
        else:
            probe = probes.get(n) or occt.FaceProbe(part.face(n).topods)
            lo, hi = probe.bbox()
            near = np.all((pts >= lo - ball - hit_tol) & (pts <= hi + ball + hit_tol), axis=1)
            depth = np.full(len(pts), -np.inf)
            skip_until = -np.inf
            for k in np.nonzero(near)[0]:
                if travel[k] < skip_until:
                    continue
                sd, _ = probe.face_distance(pts[k])
                evaluated += 1
                depth[k] = ball - sd
                skip_until = travel[k] + (sd - ball - hit_tol)
        hit = np.nonzero(depth > hit_tol)[0]
        if len(hit):
            worst = int(hit[np.argmax(depth[hit])])
            hits.append(dict(face=n, followed=n in pair, depth_mm=float(depth[worst]),
                             worst_cycle=worst, n_cycles=len(hit), cycles=_ranges(hit)))
    return dict(hits=hits, faces_checked=len(part), distances_evaluated=evaluated,
                ball_radius_mm=ball, hit_tolerance_mm=hit_tol)


def verify(toolpath, part=None, *, sample_unseeded: int = 64, hit_tolerance_mm: float = 1e-6,
           reference_spacing_mm: float = 0.01, whole_part: bool = True,
           progress=None) -> VerificationReport:
    """Check ``toolpath`` against OCCT; see the module docstring and docs/validation.md.

    ``part``: the :class:`~cadcnc.part.Part` the path was computed on (default: the STEP
    file in ``toolpath.inputs['source']``). ``sample_unseeded``: how many cycles per face
    are re-projected without seeds. ``hit_tolerance_mm``: a ball reaching deeper than this
    into a face is a hit (below it is tangency round-off). ``reference_spacing_mm``: sample
    spacing of OCCT's intersection curve. ``progress(stage, done, total)`` is called as
    stages advance.
    """
    if len(toolpath) == 0:
        raise InputError("verify: the toolpath has no points")
    part = _resolve_part(toolpath, part)
    if None in toolpath.faces:
        raise InputError("verify: the toolpath does not name its two faces")
    timer = {}
    t0 = time.perf_counter()
    probes = {n: occt.FaceProbe(part.face(n).topods) for n in toolpath.faces}
    surfaces = []
    for side, n in enumerate(toolpath.faces):
        if progress:
            progress("surfaces", side, 2)
        surfaces.append(_check_surface(probes[n], n, float(toolpath.offsets[side]),
                                       toolpath.points, toolpath.uv[:, side],
                                       sample_unseeded))
    timer["surfaces"] = time.perf_counter() - t0
    inputs = toolpath.inputs
    radius = float(inputs.get("radius", max(toolpath.offsets)))
    ball = radius + float(inputs.get("allowance", 0.0))
    edge = None
    if inputs.get("start") is None and "edge" in inputs:
        from ..geometry.part import CONCAVE

        concave = [e for e in part.shared_edges(*toolpath.faces) if e.edge_class == CONCAVE]
        edge = concave[inputs["edge"]] if inputs["edge"] < len(concave) else None
    span, target = _span(toolpath, edge)
    f_max = float(np.max(toolpath.commanded[1:])) if len(toolpath) > 1 else 1.0
    t1 = time.perf_counter()
    if progress:
        progress("reference", 0, 1)
    ref = check_reference(
        *(occt.offset_surface(probes[n], off) for n, off in zip(toolpath.faces,
                                                                toolpath.offsets)),
        toolpath.points, span=span, target=target, cover_radius=0.6 * f_max,
        spacing=reference_spacing_mm,
        residual_probes=[(probes[n], off) for n, off in zip(toolpath.faces, toolpath.offsets)])
    timer["reference"] = time.perf_counter() - t1
    edge_dev = None
    if edge is not None and max(toolpath.offsets) == 0.0:
        edge_dev = float(np.nanmax(occt.shape_distances(edge.edge, toolpath.points)))
    t2 = time.perf_counter()
    wp = (_whole_part(part, probes, toolpath, surfaces, ball, hit_tolerance_mm, progress)
          if whole_part else dict(hits=[], faces_checked=0))
    timer["whole_part"] = time.perf_counter() - t2
    timer["total"] = time.perf_counter() - t0
    return VerificationReport(
        faces=tuple(toolpath.faces), n_points=len(toolpath), radius=radius, ball_radius=ball,
        offsets=tuple(toolpath.offsets), stop_reason=toolpath.stop_reason,
        stop_detail=toolpath.stop_detail, surfaces=surfaces, reference=ref,
        feed=_check_feed(toolpath), theory=_theory(toolpath, surfaces), whole_part=wp,
        stop=_stop_check(toolpath, probes, ref, span, f_max), edge_deviation_mm=edge_dev,
        seconds=timer)


def _span(toolpath, edge):
    """How far the path was meant to go: ("closed"|"end"|"target", target point)."""
    if toolpath.stop_reason == "closed":
        return "closed", None
    if toolpath.stop_reason == "end":
        return "end", None
    if toolpath.inputs.get("end") is not None:
        return "target", np.asarray(toolpath.inputs["end"], float)
    if edge is not None:
        return ("closed", None) if edge.closed else ("target", np.asarray(edge.end, float))
    return "end", None


def _stop_check(toolpath, probes, ref, span, f_max) -> dict:
    """Where the last contacts lie, and whether that matches the stop reason."""
    last = toolpath.points[-1]
    states = []
    for side, n in enumerate(toolpath.faces):
        probe = probes[n]
        res = probe.project_seeded(last, *toolpath.uv[-1, side]) or probe.project_global(last)
        loose = occt.FaceProbe(probe.face, classify_tol=1e-4)
        states.append(loose.state(*res[:2]))
    reason = toolpath.stop_reason
    tail = ref.gaps[-1] if ref.gaps else None
    remaining = (ref.span_mm - tail[0]) if tail and tail[1] >= ref.span_mm - 1e-9 else 0.0
    consistent = None
    if reason == "boundary":
        consistent = any(s != occt.IN for s in states)
    elif reason == "closed":
        consistent = bool(np.linalg.norm(last - toolpath.points[0]) <= f_max)
    elif reason == "end":
        consistent = True
    return dict(reason=reason, last_contact_states=states, span=span,
                remaining_mm=float(remaining), consistent=consistent,
                left_face=[n for n, s in zip(toolpath.faces, states) if s != occt.IN])
