"""What the operations share: the height of link moves, running one stretch's cut, and the
program of a single path."""

from __future__ import annotations

from ..errors import GeometryError
from ..job import SAFE_MARGIN, Job
from ..program.linking import linked
from ..program.program import CutSegment, Program
from ..program.toolpath import Toolpath, toolpath_from_record
from .path.pair_path import PathPlan, stepper_for


def safe_height(part, job: Job) -> float:
    """Ball-centre Z of link moves: the job's clearance, else the part's top + SAFE_MARGIN."""
    return job.clearance if job.clearance is not None else part.top + SAFE_MARGIN


def run_stretch(plan: PathPlan, guard, max_cycles: int, progress,
                allow_empty: bool = False) -> Toolpath:
    """Run the plan's stepper with ``guard`` inside it (given to the constructor, so that
    the compiled stepper asks it before committing a step); a path of its start alone is
    an error unless ``allow_empty`` (the caller then skips it with the stop's reason)."""
    stepper = stepper_for(plan, max_cycles, True, guard=guard)
    stepper.run(progress)
    if stepper.cycles == 0 and not allow_empty:
        raise GeometryError(f"no path: the interpolator stopped at the start point "
                            f"({stepper.stop_reason}): {stepper.stop_detail}")
    return toolpath_from_record(stepper.record, plan.job, stepper.stop_reason,
                                stepper.stop_detail, plan.edge_length)


def single_cut_program(part, job: Job, path: Toolpath) -> Program:
    """The program of one path: its cut, reached from and left to the safe height. It is
    complete when the path is (a path stopped by a boundary is partial here, as asked)."""
    return Program(job, linked([CutSegment(path)], safe_height(part, job)))
