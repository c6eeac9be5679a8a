"""One path per feasible stretch of a pair, and a user's start moved into a stretch.

:func:`stretch_paths` finds every stretch of the pair's shared concave edges
(:func:`~cadcnc.ops.path.stretches.pair_stretches`) and runs the stepper once per stretch,
from its start limit to its end limit (``end=`` given, so the last step lands on it);
a closed edge feasible all around is followed once around. A pair with no stretch at
all is refused with the reason per edge (NothingToCutError, exit 3). :func:`nearest_start` moves a user's start that
lies outside every stretch to the nearest stretch limit and says so.
Units: mm.
"""

from __future__ import annotations

import numpy as np

from ...core.errors import NothingToCutError
from ...core.job import Job
from ...guard.clearance import ClearanceGuard
from ...program.toolpath import Toolpath
from .feasibility import Feasibility
from .pair_path import PathPlan, run_plan
from .stretches import EdgeStretches, Stretch, pair_stretches


def plan_for_stretch(s1, s2, job: Job, stretch: Stretch) -> PathPlan:
    """The stepper plan from a stretch's start limit to its end limit."""
    return PathPlan(s1, s2, job, stretch.start.tangency,
                    None if stretch.closed else stretch.end.tangency, stretch.closed,
                    stretch.direction, check_boundary=True, edge_length=stretch.length)


def refuse_without_stretch(s1, s2, found: list[EdgeStretches]) -> None:
    """NothingToCutError (exit 3: a valid pair, nothing to cut) naming, per edge, why no
    position is feasible (if none is)."""
    if any(e.stretches for e in found):
        return
    reasons = "; ".join(e.refusal for e in found)
    raise NothingToCutError(f"faces {s1.number} and {s2.number}: no feasible ball position "
                        f"along their shared concave edge(s): {reasons}")


def stretch_paths(s1, s2, job: Job, guard: ClearanceGuard | None = None,
                  max_cycles: int = 1_000_000, found: list[EdgeStretches] | None = None
                  ) -> list[tuple[Stretch, Toolpath]]:
    """(stretch, toolpath) for every feasible stretch of the pair, edge by edge
    (``found``: the pair's stretches when already computed).

    The stepper runs between the stretch's limits without the clearance guard: the
    stretch's limits (located to 1e-7 mm) keep the path clear of third faces, and the
    whole-part gouge gate stays the final check.
    """
    if found is None:
        found = pair_stretches(s1, s2, job, guard)
    refuse_without_stretch(s1, s2, found)
    return [(st, run_plan(plan_for_stretch(s1, s2, job, st), max_cycles))
            for edge in found for st in edge.stretches]


def nearest_start(found: list[EdgeStretches], feas: Feasibility, point):
    """(tangency, note) for a user's start ``point``: the tangency through it when that
    position is feasible (note ""), else the nearest stretch limit and a note saying so.

    ``feas`` judges the position (see :class:`~cadcnc.ops.path.feasibility.Feasibility`).
    """
    point = np.asarray(point, dtype=float)
    limits = [lim for e in found for st in e.stretches for lim in (st.start, st.end)]
    if not limits:
        raise NothingToCutError("no feasible stretch to start in: "
                            + "; ".join(e.refusal for e in found))
    nearest = min(limits, key=lambda lim: float(np.linalg.norm(np.subtract(lim.p, point))))
    edge_samples = [x for e in found for x in e.samples if x.tangency is not None]
    near = min(edge_samples, key=lambda x: float(np.linalg.norm(
        np.subtract(x.tangency.p, point))), default=None)
    if near is not None:
        here = feas.sample(near.s, point, near.tangent, near.tangency)
        if here.ok:
            return here.tangency, ""
        why = f"{here.rule}: {here.detail}"
    else:
        why = "no tangency near it"
    away = float(np.linalg.norm(np.subtract(nearest.p, point)))
    p = ", ".join(f"{v:.4f}" for v in point)
    q = ", ".join(f"{v:.4f}" for v in nearest.p)
    return nearest.tangency, (f"start ({p}) is outside every feasible stretch ({why}): "
                              f"moved to the nearest stretch limit ({q}), {away:.4f} mm "
                              "away")
