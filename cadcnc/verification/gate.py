"""The whole-part gouge gate: may this path be written? Fails closed.

:func:`gouge_gate` runs only the checks that measure gouges: each face of the pair
against its offset (trimmed face included) and the ball against every face of the part.
It skips OCCT's intersection reference, the expensive part of
:func:`~cadcnc.verification.verify`, so that a CLI can call it before writing every path.
The answer is ``ok`` only when the check completed and measured a finite depth within the
limit: an exception inside the check, or a depth it could not measure, refuses the path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..tolerances import Tolerances
from .records import WholePartHit, deepest, strict_max
from .surface_checks import SAMPLE_UNSEEDED, check_pair, prepare
from .whole_part import check_whole_part


@dataclass(frozen=True)
class GateResult:
    """The gate's answer.

    ``ok``: the ball cuts no face of the part deeper than ``limit_mm`` (``Tolerances.gouge``)
    and the check completed. ``depth_mm``: the deepest cut into any face, the pair's own
    trimmed faces included (nan when unmeasured); ``hits`` every face cut deeper than
    ``Tolerances.hit``. ``message``: empty when ok, else why the path is refused
    ("refused: the ball cuts into the part (face 5 by 2 mm over 601 cycles) beyond
    0.001 mm; nothing written").
    """

    ok: bool
    depth_mm: float
    hits: list[WholePartHit] = field(default_factory=list)
    limit_mm: float = math.nan
    message: str = ""


def gouge_gate(toolpath, part=None, tol: Tolerances | None = None, *,
               progress=None) -> GateResult:
    """Whether ``toolpath`` clears every face of ``part`` within ``tol.gouge`` (fails closed).

    ``part`` defaults to the STEP file the toolpath's job names; ``tol`` to the job's
    tolerances. ``progress(stage, done, total)`` is called as the checks advance.
    """
    limit = math.nan
    try:
        tol = toolpath.job.tolerances if tol is None else tol
        limit = float(tol.gouge)
        part, probes = prepare(toolpath, part, tol)
        surfaces = check_pair(toolpath, probes, tol, SAMPLE_UNSEEDED, progress)
        whole = check_whole_part(part, probes, toolpath, surfaces, toolpath.job.tool.offset,
                                 tol, progress)
        overcut = strict_max(s.max_overcut_mm for s in surfaces)
        depth = deepest(overcut, whole.hits)
    except Exception as e:  # noqa: BLE001 - any failure refuses the path
        return GateResult(False, math.nan, [], limit,
                          _incomplete(f"{type(e).__name__}: {e}"))
    if not math.isfinite(depth) or not math.isfinite(limit):
        unknown = [h.face for h in whole.hits if not math.isfinite(h.depth_mm)]
        why = (f"the depth into face{'s' if len(unknown) > 1 else ''} "
               f"{', '.join(map(str, unknown))} could not be measured" if unknown
               else f"the depth measured is {depth}")
        return GateResult(False, depth, whole.hits, limit, _incomplete(why))
    if depth <= limit:
        return GateResult(True, depth, whole.hits, limit)
    deep = [h for h in whole.hits if h.depth_mm > limit]
    what = "; ".join(f"face {h.face} by {h.depth_mm:.4g} mm over {h.n_cycles} cycles"
                     for h in deep) or f"over-cut {overcut:.4g} mm"
    return GateResult(False, depth, whole.hits, limit,
                      f"refused: the ball cuts into the part ({what}) beyond {limit:g} mm; "
                      "nothing written")


def _incomplete(why: str) -> str:
    return (f"refused: the whole-part gouge check could not be completed ({why}); "
            "nothing written")
