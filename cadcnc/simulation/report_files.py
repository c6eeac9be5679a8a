"""A simulation's outputs by suffix (.json report, .png, .glb, .stl), written all or none
(:class:`~cadcnc.io.output_set.OutputSet`)."""

from __future__ import annotations

import json
from pathlib import Path

from ..core.jsonable import plain
from ..io.output_set import OutputSet
from ..io.simulation_plot import SUFFIXES, glb_bytes, png_bytes, stl_bytes
from .stock_mesh import dexel_mesh
from .stock_report import SimulationReport


def check_outputs(outs, inputs=()) -> OutputSet:
    """The outputs checked before any work (exit 4 or 2 when one cannot be written)."""
    return OutputSet(outs, SUFFIXES, inputs=inputs)


def render(report: SimulationReport, part, out, title: str = "") -> str | bytes:
    """One output's contents, by its suffix."""
    suffix = Path(out).suffix.lower()
    s = report.samples
    if suffix == ".json":
        return json.dumps(plain(report.to_dict(), nonfinite_as_strings=True), indent=1) + "\n"
    if suffix == ".png":
        return png_bytes(part, s.point, s.left, report.data["gouges"],
                         report.data["threshold_mm"], title)
    mesh = dexel_mesh(report.stock)
    if suffix == ".glb":
        return glb_bytes(part, s.point, s.left, report.gouge_points, mesh,
                         report.data["threshold_mm"])
    return stl_bytes(mesh)


def write_outputs(report: SimulationReport, part, outputs: OutputSet, title: str = "") -> None:
    """Every output of ``outputs`` rendered, then written at once."""
    outputs.write({d: render(report, part, d, title) for d in outputs.destinations})
