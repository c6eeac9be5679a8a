"""The verdict of :func:`~cadcnc.verification.verify`: every criterion against its limit.

- **gouge**: the deepest cut of the ball into any face of the part, at the centres and
  along the moves (material-aware), against ``Tolerances.gouge``; the moves' proven
  bound must be within it too.
- **deviation**: the largest over-cut and under-cut of the followed faces at the cutter
  centres against ``Tolerances.accuracy`` (the chord between points belongs to
  Hausdorff).
- **hausdorff**: the two-sided Hausdorff distance between the path polyline and OCCT's
  intersection of the offset surfaces over the path's own span (chord sag included)
  against ``Tolerances.hausdorff``.
- **coverage**: the curve coverage over the path's own span against
  ``Tolerances.coverage``.

A value that could not be measured (nan) fails. Lengths in mm; coverage a fraction.
"""

from __future__ import annotations

import math

from .check_records import Criterion


def criteria(rep, gouge_mm: float | None = None) -> list[Criterion]:
    """Every criterion of the report ``rep``; ``gouge_mm`` overrides the gouge limit."""
    tol = rep.tolerances
    gouge = tol.gouge if gouge_mm is None else gouge_mm
    out = []
    depth = rep.max_gouge_mm
    bound = rep.sweep.depth_bound_mm if rep.sweep is not None else -math.inf
    unproven = depth <= gouge and not bound <= gouge
    out.append(Criterion("gouge", depth, gouge, bool(depth <= gouge) and not unproven,
                         f"the moves are bounded only by {bound:.3g} mm" if unproven
                         else ""))
    dev = _max(rep.max_overcut_mm, rep.max_undercut_mm)
    out.append(Criterion("deviation", dev, tol.accuracy, bool(dev <= tol.accuracy),
                         f"over-cut {rep.max_overcut_mm:.3g}, under-cut "
                         f"{rep.max_undercut_mm:.3g} mm"))
    h = rep.hausdorff_mm
    out.append(Criterion("hausdorff", h, tol.hausdorff, bool(h <= tol.hausdorff),
                         rep.reference.note))
    cov = rep.coverage
    out.append(Criterion("coverage", cov, tol.coverage, bool(cov >= tol.coverage),
                         f"of {rep.reference.own_span_mm:.3f} mm"))
    return out


def _max(a: float, b: float) -> float:
    return math.nan if math.isnan(a) or math.isnan(b) else max(a, b)
