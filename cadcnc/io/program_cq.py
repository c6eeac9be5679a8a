"""A :class:`~cadcnc.program.program.Program` as CadQuery wires, for ``show_object``.

The program stage imports no OCCT; this writer does. Each cut becomes one polyline wire
through its ball centres (mm), each link one polyline wire through its moves; points
closer than 1 µm to the previous one are dropped (OCCT refuses zero-length edges).
"""

from __future__ import annotations

import numpy as np

from ..core.errors import require
from ..program.program import Program

MIN_EDGE = 1e-3  # mm: a shorter move is merged into the next


def _wire(points: np.ndarray):
    import cadquery as cq

    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    keep = [pts[0]]
    for p in pts[1:]:
        if np.linalg.norm(p - keep[-1]) >= MIN_EDGE:
            keep.append(p)
    if len(keep) < 2:
        return None
    return cq.Wire.makePolygon([cq.Vector(*map(float, p)) for p in keep])


def to_cq(program: Program, cuts: bool = True, links: bool = True) -> list:
    """CadQuery wires of ``program``'s segments in machining order: one per cut (ball
    centres) when ``cuts``, one per link when ``links``; segments shorter than 1 µm are
    left out."""
    require("program", program, Program, "a cadcnc Program")
    wires = []
    for seg in program.segments:
        if not (cuts if seg.kind == "cut" else links):
            continue
        w = _wire(seg.points)
        if w is not None:
            wires.append(w)
    return wires


def to_cq_compound(program: Program, cuts: bool = True, links: bool = True):
    """One CadQuery Compound of :func:`to_cq`'s wires (one object for ``show_object``)."""
    import cadquery as cq

    return cq.Compound.makeCompound(to_cq(program, cuts, links))


def show_program(show, program: Program, part=None) -> None:
    """Show a program in CQ-editor: ``show`` is its ``show_object``; the part (a Workplane,
    Shape or Part, optional) translucent, the cuts in red, the links in blue."""
    if part is not None:
        from ..geometry.part import Part

        if isinstance(part, Part):   # CQ-editor shows CadQuery objects: its OCCT shape
            import cadquery as cq
            part = cq.Shape.cast(part.shape)
        show(part, name="part", options={"alpha": 0.6})
    show(to_cq_compound(program, links=False), name="cuts", options={"color": "red"})
    if program.links:
        show(to_cq_compound(program, cuts=False), name="links", options={"color": "blue"})
