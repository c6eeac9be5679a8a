"""From two faces and machining parameters to a stepper or a whole toolpath.

Resolves the faces (part faces, CadQuery faces), checks that they make a pair a ball can
follow, solves the start and end tangencies (defaults: the ends of the shared concave
edge), and runs the :class:`~cadcnc.interp.stepper.Stepper` loop. Units: radius, allowance,
points in mm; feed in mm/min; period in s.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...core.errors import FacePairError, GeometryError, InputError, StartPointError
from ...core.job import Job, PairPath, Tool
from ...core.progress import Progress
from ...core.tolerances import DEFAULT, Tolerances
from ...geometry.face_surface import FaceSurface
from ...geometry.part import CONCAVE
from ...interp.compiled import new_stepper
from ...interp.stepper import Stepper, Tangency
from ...interp.tangency import solve_tangency
from ...program.toolpath import Toolpath, toolpath_from_record


@dataclass(frozen=True)
class PathPlan:
    """Everything the stepper needs, resolved: surfaces, offsets, start, end, direction."""

    s1: FaceSurface
    s2: FaceSurface
    job: Job
    start: Tangency
    end: Tangency | None
    closed: bool
    direction: tuple[float, float, float]
    check_boundary: bool = True
    edge_length: float | None = None   # mm: the shared edge followed (default start/end)

    @property
    def length_estimate(self) -> float | None:
        """The path's length before running it, mm: the edge's length when it follows one,
        else the straight distance from start to end (None from a start alone)."""
        if self.edge_length is not None:
            return self.edge_length
        if self.end is not None and not self.closed:
            return float(np.linalg.norm(np.subtract(self.end.p, self.start.p)))
        return None

    @property
    def offsets(self) -> tuple[float, float]:
        return self.job.offsets


def _surface(face, tol: Tolerances) -> FaceSurface:
    return face if isinstance(face, FaceSurface) else FaceSurface(face, tol=tol)


def _label(s: FaceSurface, fallback: str) -> str:
    return f"face {s.number}" if s.number else fallback


def shared_edge_for(s1: FaceSurface, s2: FaceSurface, edge: int = 0):
    """The ``edge``-th shared concave edge of two faces of one part, or FacePairError."""
    part = s1.part
    if part is None or s2.part is not part:
        raise FacePairError("the two faces are not faces of one part: give start and end "
                            "points")
    i, j = s1.number, s2.number
    edges = part.shared_edges(i, j)
    if not edges:
        raise FacePairError(
            f"{part.source}: faces {i} and {j} are not adjacent (they share no edge); pick a "
            "concave pair from `cadcnc faces`, or give start and end points near their "
            "intersection")
    concave = [e for e in edges if e.edge_class == CONCAVE]
    if not concave:
        kinds = ", ".join(sorted({e.edge_class for e in edges}))
        lo = min(e.angle_range_deg[0] for e in edges)
        hi = max(e.angle_range_deg[1] for e in edges)
        raise FacePairError(
            f"{part.source}: faces {i} and {j} meet along a {kinds} edge (material angle "
            f"{lo:.1f}..{hi:.1f} deg): a ball cannot sit in that corner; pick a concave pair "
            "(material angle > 180 deg) from `cadcnc faces`")
    if not 0 <= edge < len(concave):
        raise InputError(f"there is no concave edge number {edge + 1} (index {edge}): faces "
                         f"{i} and {j} share {len(concave)} concave edge(s)")
    return concave[edge]


def pair_job(face_a, face_b, *, radius: float, allowance: float = 0.0, feed: float,
             period: float, start=None, end=None, offsets=None, edge: int = 0,
             tol: Tolerances = DEFAULT) -> tuple[FaceSurface, FaceSurface, Job]:
    """The two faces as surfaces and the validated :class:`Job` of keyword arguments (one
    path: ``edge`` is one index; a program takes None for every edge)."""
    if edge is None:
        raise InputError("edge must be an index >= 0 among the shared concave edges: one "
                         "path follows one edge (cadcnc.ops.path.pair_program.program_for_job "
                         "follows every stretch of every edge)")
    tool = Tool(radius, allowance)
    op = PairPath(offsets=(None, None) if offsets is None else offsets, start=start, end=end,
                  edge=edge)
    job = Job(tool, feed, period, op, tolerances=tol)
    s1, s2 = _surface(face_a, tol), _surface(face_b, tol)
    op = replace(op, faces=(s1.number, s2.number))
    return s1, s2, replace(job, operation=op, source=getattr(s1.part, "source", None))


def plan_path(s1: FaceSurface, s2: FaceSurface, job: Job) -> PathPlan:
    """Solve the start/end tangencies of ``job`` on two surfaces (Newton, to ``tol.start``)."""
    tol, op = job.tolerances, job.operation
    offs = job.offsets
    start, end = op.start, op.end
    closed = False
    edge_length = None
    if start is None:
        e = shared_edge_for(s1, s2, op.edge or 0)  # None (every edge): the first
        edge_length = float(e.length)
        anchors = [(e.start, e.start_tangent), (None if e.closed else (e.end, e.end_tangent))]
        direction, closed = e.start_tangent, e.closed
    else:
        anchors = [(start, None), (None if end is None else (end, None))]
        direction = None
    solved = []
    for which, anchor in zip(("start", "end"), anchors):
        if anchor is None:
            solved.append(None)
            continue
        point, tangent = anchor
        seeds = [s.project(point)[:2] for s in (s1, s2)]
        tan = solve_tangency(s1, s2, offs, *seeds, point, direction=tangent, tol=tol,
                             what=which)
        for s, uv, label in ((s1, tan.uv1, _label(s1, "surface 1")),
                             (s2, tan.uv2, _label(s2, "surface 2"))):
            # an end beyond a face is fine: the path stops where the contact leaves it
            if which == "start" and not s.contains(*uv):
                raise StartPointError(
                    f"{which}: at the {which} tangency ({', '.join(f'{v:.4f}' for v in tan.p)})"
                    " the ball "
                    f"touches {label} outside the face (its contact lies beyond the face's "
                    f"boundary); give a {which} point further inside the intersection")
        solved.append(tan)
    t_start, t_end = solved
    if t_end is None and start is not None:
        closed = True  # a user start without an end: stop if the path comes back to it
    if direction is None:
        n1 = s1.normal(*t_start.uv1)
        n2 = s2.normal(*t_start.uv2)
        m = np.cross(n1, n2)
        if t_end is not None and m @ (np.array(t_end.p) - np.array(t_start.p)) < 0:
            m = -m
        direction = m
    # With both offsets 0 along a shared edge the contacts run on the faces' common
    # boundary by construction: the boundary rule cannot apply, the edge's ends bound it.
    on_edge = start is None and offs == (0.0, 0.0)
    return PathPlan(s1, s2, job, t_start, t_end, closed, tuple(map(float, direction)),
                    check_boundary=not on_edge, edge_length=edge_length)


def make_stepper(face_a, face_b, *, radius: float, allowance: float = 0.0, feed: float,
                 period: float, start=None, end=None, offsets=None, edge: int = 0,
                 tol: Tolerances = DEFAULT, max_cycles: int = 1_000_000,
                 record: bool = True) -> Stepper:
    """A :class:`Stepper` ready to be driven one period at a time (real-time use)."""
    s1, s2, job = pair_job(face_a, face_b, radius=radius, allowance=allowance, feed=feed,
                           period=period, start=start, end=end, offsets=offsets, edge=edge,
                           tol=tol)
    return stepper_for(plan_path(s1, s2, job), max_cycles, record)


def check_cycle_count(plan: PathPlan, max_cycles: int) -> None:
    """Refuse, before running, a job whose path needs more cycles than ``max_cycles``.

    The estimate is the plan's length estimate over the commanded step f = F Ts (steps
    the accuracy rule shortens come on top). InputError names the feed and the period.
    """
    length = plan.length_estimate
    job = plan.job
    if length is None or length <= 0.0:
        return
    cycles = length / job.step
    if cycles > max_cycles:
        raise InputError(
            f"the path is about {length:.4g} mm long: at feed {job.feed:g} mm/min and "
            f"period {job.period:g} s (a step of {job.step:.3g} mm) it needs about "
            f"{cycles:.3g} cycles, over the limit of {max_cycles}: raise the feed or the "
            "period, or the cycle limit (--max-cycles)")


def stepper_for(plan: PathPlan, max_cycles: int = 1_000_000, record: bool = True, *,
                check_cycles: bool = True, guard=None) -> Stepper:
    """The stepper of a solved plan; InputError when its cycle estimate exceeds the limit
    (``check_cycles=False`` for a deliberately short run of a longer path). ``guard``: the
    collision stop's guard, given here (the compiled stepper reads it when built)."""
    if check_cycles:
        check_cycle_count(plan, max_cycles)
    job = plan.job
    return new_stepper(plan.s1, plan.s2, plan.offsets, plan.start, feed=job.feed,
                   period=job.period, direction=plan.direction, end=plan.end,
                   closed=plan.closed, tol=job.tolerances, max_cycles=max_cycles,
                   record=record, check_boundary=plan.check_boundary, guard=guard)


def run_plan(plan: PathPlan, max_cycles: int = 1_000_000,
             progress: Progress | None = None) -> Toolpath:
    """Run the stepper of a plan to its stop; the toolpath with its error bounds.
    ``progress(cycles, 0, "<mm> mm")`` every 10 000 cycles."""
    stepper = stepper_for(plan, max_cycles, True).run(progress)
    if stepper.cycles == 0:
        raise GeometryError(f"no path: the interpolator stopped at the start point "
                            f"({stepper.stop_reason}): {stepper.stop_detail}")
    return toolpath_from_record(stepper.record, plan.job, stepper.stop_reason,
                                stepper.stop_detail, plan.edge_length)


def intersection_path(face_a, face_b, *, radius: float, allowance: float = 0.0, feed: float,
                      period: float, start=None, end=None, offsets=None, edge: int = 0,
                      tol: Tolerances = DEFAULT, max_cycles: int = 1_000_000,
                      progress: Progress | None = None) -> Toolpath:
    """The ball-end cutter path along the intersection of two faces (the paper's method).

    ``face_a``/``face_b``: part faces (``part.face(n)``), CadQuery faces or TopoDS faces.
    ``radius``, ``allowance`` in mm; ``feed`` in mm/min; ``period`` in s (feed 1500 and
    period 0.004 give the paper's 0.1 mm step). ``start``/``end``: points (mm) near the
    intersection; by default the ends of the faces' shared concave edge number ``edge``
    (0-based; a closed edge is followed once around). ``offsets``: per-surface offset
    distance, None meaning R + C; 0 makes that face a guide surface carrying the cutter
    centre. ``progress(cycles, 0, "<mm> mm")`` is called every 10 000 cycles.
    """
    s1, s2, job = pair_job(face_a, face_b, radius=radius, allowance=allowance, feed=feed,
                           period=period, start=start, end=end, offsets=offsets, edge=edge,
                           tol=tol)
    return run_plan(plan_path(s1, s2, job), max_cycles, progress)


def path_for_job(part, job: Job, max_cycles: int = 1_000_000,
                 progress: Progress | None = None) -> Toolpath:
    """The toolpath of a ``job`` whose operation names two faces of ``part``."""
    i, j = job.operation.faces
    if i is None or j is None:
        raise InputError("the job names no faces: give the two face numbers")
    return run_plan(plan_path(part.face(i), part.face(j), job), max_cycles, progress)


def intersection_paths(face_a, face_b, **kwargs) -> list[Toolpath]:
    """One toolpath per shared concave edge of two adjacent part faces."""
    s1 = _surface(face_a, kwargs.get("tol", DEFAULT))
    s2 = _surface(face_b, kwargs.get("tol", DEFAULT))
    shared_edge_for(s1, s2)
    n = sum(e.edge_class == CONCAVE for e in s1.part.shared_edges(s1.number, s2.number))
    return [intersection_path(s1, s2, edge=k, **kwargs) for k in range(n)]
