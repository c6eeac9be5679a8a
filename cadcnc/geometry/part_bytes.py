"""A part as bytes, to rebuild it in a worker process (OCCT shapes do not pickle).

:func:`part_blob` writes the shape the part was made from (before any sewing) in OCCT's
binary BRep format with what else the part was built with; :func:`part_from_blob` builds
the same :class:`~cadcnc.geometry.part.Part` from it: the same faces in the same order
(the format keeps sub-shapes, their order and orientations), so face numbers agree
between processes.
"""

from __future__ import annotations

import io

from OCP.BinTools import BinTools, BinTools_FormatVersion
from OCP.TopoDS import TopoDS_Shape

from .part import Part


def part_blob(part: Part) -> tuple:
    """(BRep bytes, source, tolerances, flip_material, warnings): the arguments of
    :func:`part_from_blob`; all of them pickle."""
    stream = io.BytesIO()
    BinTools.Write_s(part.given_shape, stream, False, False,
                     BinTools_FormatVersion.BinTools_FormatVersion_CURRENT)
    return (stream.getvalue(), part.source, part.tol, part.flip_material,
            list(part.warnings))


def part_from_blob(blob: bytes, source: str, tol, flip_material: bool,
                   warnings: list | None = None) -> Part:
    """The :class:`Part` of :func:`part_blob`'s answer."""
    shape = TopoDS_Shape()
    BinTools.Read_s(shape, io.BytesIO(blob))
    part = Part(shape, source=source, tol=tol, flip_material=flip_material)
    part.warnings = list(warnings or [])
    return part
