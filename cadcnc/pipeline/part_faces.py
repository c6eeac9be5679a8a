"""A part's faces, neighbours and concave pairs (``cadcnc faces``). It reads the part only:
neither the interpolation core nor numba is imported, so it starts fast."""

from __future__ import annotations

from ..geometry.faces_report import faces_report
from ..geometry.part import load_step


def faces_of(step, flip_material: bool = False) -> tuple[dict, list[str]]:
    """(report, warnings): :func:`~cadcnc.geometry.faces_report.faces_report` of the STEP file
    ``step`` and what OCCT's STEP reader warned of."""
    part = load_step(step, flip_material=flip_material)
    return faces_report(part), list(part.warnings)
