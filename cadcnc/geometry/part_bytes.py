"""A part as bytes, to rebuild it in a worker process (OCCT shapes do not pickle).

:func:`part_blob` writes the shape the part was made from (before any sewing) in OCCT's
binary BRep format with what else the part was built with; :func:`part_from_blob` builds
the same :class:`~cadcnc.geometry.part.Part` from it: the same faces in the same order
(the format keeps sub-shapes, their order and orientations), so face numbers agree
between processes. A part turned into a setup (:mod:`.setup`) is written as its original
and its setup, and rebuilt turned the same way: the worker's part is in the same (work)
coordinates as the caller's, and ``setup_part`` with the same job leaves it as it is
(a plain part of the turned shape would be turned a second time).
"""

from __future__ import annotations

import io

from OCP.BinTools import BinTools, BinTools_FormatVersion
from OCP.TopoDS import TopoDS_Shape

from .part import Part
from .setup import Setup, setup_in, setup_part


def part_blob(part: Part) -> tuple:
    """(BRep bytes, source, tolerances, flip_material, warnings, setup dict or None): the
    arguments of :func:`part_from_blob`; all of them pickle."""
    setup = setup_in(part)
    if setup is not None:
        return (*part_blob(part.original)[:5], setup.to_dict())
    stream = io.BytesIO()
    BinTools.Write_s(part.given_shape, stream, False, False,
                     BinTools_FormatVersion.BinTools_FormatVersion_CURRENT)
    return (stream.getvalue(), part.source, part.tol, part.flip_material,
            list(part.warnings), None)


def part_from_blob(blob: bytes, source: str, tol, flip_material: bool,
                   warnings: list | None = None, setup: dict | None = None) -> Part:
    """The :class:`Part` of :func:`part_blob`'s answer (turned into ``setup`` if given)."""
    shape = TopoDS_Shape()
    BinTools.Read_s(shape, io.BytesIO(blob))
    part = Part(shape, source=source, tol=tol, flip_material=flip_material)
    part.warnings = list(warnings or [])
    return part if setup is None else setup_part(part, Setup.from_dict(setup))
