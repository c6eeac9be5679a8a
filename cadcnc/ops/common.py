"""What the operations share: the ball checked up front, the cycles estimated up front, the
height of link moves, running one stretch's cut, and the program of a single path."""

from __future__ import annotations

from ..core.errors import GeometryError, InputError
from ..core.job import SAFE_MARGIN, Job
from ..core.work_limits import MAX_CYCLES, refuse_over
from ..program.linking import linked
from ..program.program import CutSegment, Program
from ..program.toolpath import Toolpath, toolpath_from_record
from .path.pair_path import PathPlan, stepper_for

CHAIN_GAP = 1e-3
"""mm: a pencil cut starting this near another's end continues it (no lift)."""
FINISH_JOIN = 1e-6
"""mm: a finishing cut starting this near the last one's end continues it (one pass or
level, chained); also the gap of a finishing program relinked once cut back."""


def require_ball(job: Job) -> None:
    """InputError unless the ball has a size: R' = R + C > 0 mm. A ball of R' = 0 runs its
    centre on the faces, no curvature limits it and no move between its points can be
    proven clear of the part (the gate refuses every one)."""
    if not job.tool.offset > 0.0:
        raise InputError(f"radius: a ball of R' = R + C = {job.tool.offset:g} mm has no size "
                         "(its centre runs on the faces and no move can be proven clear of "
                         "the part): give a radius > 0 mm")


def refuse_cycles(lengths_mm, job: Job, what: str, max_cycles: int = MAX_CYCLES) -> float:
    """The cycles ``job``'s step needs for paths of ``lengths_mm`` in all (their sum over
    the step F Ts, the commanded step; the accuracy rule's shorter steps come on top),
    refused up front (:class:`~cadcnc.core.work_limits.WorkLimitError`) over ``max_cycles``."""
    total = float(sum(lengths_mm))
    cycles = total / job.step
    refuse_over(f"{what}: {total:.4g} mm of corners at a step of {job.step:.3g} mm",
                cycles, max_cycles, "interpolation cycles",
                "raise --feed or --period (a longer step), or the cycle limit (--max-cycles)")
    return cycles


def safe_height(part, job: Job) -> float:
    """Ball-centre Z of link moves: the job's clearance, else the part's top + SAFE_MARGIN."""
    return job.clearance if job.clearance is not None else part.top + SAFE_MARGIN


def run_stretch(plan: PathPlan, guard, max_cycles: int, steps,
                allow_empty: bool = False) -> Toolpath:
    """Run the plan's stepper with ``guard`` inside it (given to the constructor, so that
    the compiled stepper asks it before committing a step); a path of its start alone is
    an error unless ``allow_empty`` (the caller then skips it with the stop's reason);
    ``steps``: the stepper's progress (``Progress``: cycles, 0, the distance), or None."""
    stepper = stepper_for(plan, max_cycles, True, guard=guard)
    stepper.run(steps)
    if stepper.cycles == 0 and not allow_empty:
        raise GeometryError(f"no path: the interpolator stopped at the start point "
                            f"({stepper.stop_reason}): {stepper.stop_detail}")
    return toolpath_from_record(stepper.record, plan.job, stepper.stop_reason,
                                stepper.stop_detail, plan.edge_length)


def single_cut_program(part, job: Job, path: Toolpath) -> Program:
    """The program of one path: its cut, reached from and left to the safe height. It is
    complete when the path is (a path stopped by a boundary is partial here, as asked)."""
    return Program(job, linked([CutSegment(path)], safe_height(part, job)))
