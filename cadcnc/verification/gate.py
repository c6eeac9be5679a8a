"""The whole-part gouge gate: may this path be written? Fails closed.

:func:`gouge_gate` runs only the checks that measure gouges: each face of the pair
against its offset (trimmed face included), the ball against every face of the part at
every centre (material-aware: OCCT's solid classifier decides which centres are in the
material), and the ball swept along every straight move actually commanded, bounded
(not sampled) between the points. It skips OCCT's intersection reference, the expensive
part of :func:`~cadcnc.verification.verify`, so that a CLI can call it before writing
every path. The answer is ``ok`` only when the check completed and proved every depth
within the limit: an exception inside the check, or a depth it could not measure,
refuses the path. docs/notes/gate.md states what is checked and the bound it uses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..core.errors import require
from ..core.tolerances import Tolerances
from ..program.toolpath import Toolpath
from .check_records import SweepCheck, WholePartHit, strict_max
from .gate_cache import cache_for, toolpath_key
from .surface_checks import SAMPLE_UNSEEDED, check_pair, prepare, resolve_part
from .whole_part import check_whole_part


@dataclass(frozen=True)
class GateResult:
    """The gate's answer.

    ``ok``: the ball cuts no face of the part deeper than ``limit_mm`` (``Tolerances.gouge``)
    at any centre, the swept ball along every move is proven within ``limit_mm`` less
    ``blend_mm``, and the check completed. ``depth_mm``: the deepest cut measured into any
    face (centres, and moves where they were examined; nan when unmeasured); ``hits``
    every face cut deeper than ``Tolerances.hit`` at a centre; ``sweep`` the moves' check
    (its ``depth_bound_mm`` the proven bound). ``in_material``: the depth reaches R' less
    the limit: some centre or move lies in, on or within the limit of the material, where
    no smaller radius can help. ``message``: empty when ok,
    else why the path is refused ("refused: the ball cuts into the part (face 5 by 2 mm
    over 601 cycles) beyond 0.001 mm; nothing written").
    """

    ok: bool
    depth_mm: float
    hits: list[WholePartHit] = field(default_factory=list)
    limit_mm: float = math.nan
    message: str = ""
    sweep: SweepCheck | None = None
    blend_mm: float = 0.0
    in_material: bool = False


def gouge_gate(toolpath, part=None, tol: Tolerances | None = None, *, moves=None,
               blend_mm: float = 0.0, progress=None, reference: bool = False,
               before=None) -> GateResult:
    """Whether ``toolpath`` clears every face of ``part`` within ``tol.gouge`` (fails closed).

    ``part`` defaults to the STEP file the toolpath's job names; ``tol`` to the job's
    tolerances. ``moves``: (M, 3) ball-centre positions actually commanded, in order
    (after point dropping, rounding, the tool-tip offset taken back to centres, and the
    links); default the toolpath's points. ``blend_mm``: how far the machine may leave the
    programmed polyline (G64 P), counted against the limit: every move must keep the ball
    within ``tol.gouge - blend_mm`` of the part. ``progress(done, total, stage)`` is called
    as the checks advance ("surfaces", "whole part", "moves"). ``reference``: the gate
    as it was before its work was shared (:mod:`.gate_cache`) and bounded (a sampled
    cycle's exact distance always measured): the same answers, kept to test that.
    ``before``: (point, uv, faces) of the centre the moves start beside, the previous
    cut's last (:func:`~.whole_part.before_floors`; not with ``reference``).
    """
    require("toolpath", toolpath, Toolpath, "a cadcnc Toolpath")
    limit = math.nan
    blend = blend_mm
    try:
        tol = toolpath.job.tolerances if tol is None else tol
        limit = float(tol.gouge)
        blend = float(blend_mm)
        if not (math.isfinite(blend) and blend >= 0):
            raise ValueError(f"the blending tolerance must be a finite length >= 0 mm, got "
                             f"{blend_mm!r}")
        if reference:
            part, probes = prepare(toolpath, part, tol)
            surfaces = check_pair(toolpath, probes, tol, SAMPLE_UNSEEDED, progress)
            shared, before = {}, None
        else:
            part = resolve_part(toolpath, part)
            cache = cache_for(part, tol)
            part, probes = prepare(toolpath, part, tol, cache.faces.probe)
            key = toolpath_key(toolpath)
            surfaces = cache.surfaces.get(key)
            if surfaces is None:
                surfaces = check_pair(toolpath, probes, tol, SAMPLE_UNSEEDED, progress,
                                      bounded=True)
                cache.surfaces[key] = surfaces
            shared = dict(faces=cache.faces, material=cache.material)
        whole, sweep = check_whole_part(part, probes, toolpath, surfaces,
                                        toolpath.job.tool.offset, tol, progress, moves=moves,
                                        limit=limit, blend=blend, before=before, **shared)
        depth = strict_max([whole.max_depth_mm, sweep.depth_mm])
    except Exception as e:  # noqa: BLE001 - any failure refuses the path
        return GateResult(False, math.nan, [], limit,
                          _incomplete(f"{type(e).__name__}: {e}"), blend_mm=blend)
    ball = toolpath.job.tool.offset
    inside = bool(depth >= ball - limit)  # a centre within the limit of the material
    result = dict(hits=whole.hits, limit_mm=limit, sweep=sweep, blend_mm=blend,
                  in_material=inside)
    unknown = [h.face for h in whole.hits if math.isnan(h.depth_mm)]
    unknown += [h.face for h in sweep.hits if math.isnan(h.depth_mm) and h.face not in unknown]
    if unknown or not math.isfinite(limit) or math.isnan(depth):
        why = (f"the depth into face{'s' if len(unknown) > 1 else ''} "
               f"{', '.join(map(str, unknown))} could not be measured" if unknown
               else f"the depth measured is {depth}")
        return GateResult(False, depth, message=_incomplete(why), **result)
    if depth <= limit and sweep.proven:
        return GateResult(True, depth, **result)
    what = [f"face {h.face} by {h.depth_mm:.4g} mm over {h.n_cycles} cycles"
            for h in whole.hits if h.depth_mm > limit]
    named = {h.face for h in whole.hits if h.depth_mm > limit}
    what += [f"face {h.face} by {h.depth_mm:.4g} mm along {h.n_moves} "
             f"move{'s' if h.n_moves > 1 else ''} between points"
             for h in sweep.hits if h.face not in named and h.depth_mm > sweep.allowance_mm]
    counted = f" less the blending tolerance {blend:g} mm" if blend else ""
    if what:
        return GateResult(False, depth, message=(
            f"refused: the ball cuts into the part ({'; '.join(what)}) beyond {limit:g} mm"
            f"{counted}; nothing written"), **result)
    why = (f"a ball of radius R' = {ball:g} mm runs on the faces: the chords between its "
           "points cannot be bounded" if ball <= sweep.allowance_mm else
           "a move could not be measured exactly")
    return GateResult(False, depth, message=(
        f"refused: the moves are not proven within {limit:g} mm{counted} ({why}; the "
        f"bound reaches {sweep.depth_bound_mm:.4g} mm); nothing written"), **result)


def _incomplete(why: str) -> str:
    return (f"refused: the whole-part gouge check could not be completed ({why}); "
            "nothing written")
