"""A part as bytes, to rebuild it in a worker process (OCCT shapes do not pickle).

:func:`part_blob` writes the shape the part was made from (before any sewing) in OCCT's
binary BRep format with what else the part was built with; :func:`part_from_blob` builds
the same :class:`~cadcnc.geometry.part.Part` from it: the same faces in the same order
(the format keeps sub-shapes, their order and orientations), so face numbers agree
between processes. A part turned into a setup (:mod:`.setup`) is written as its original
and its setup, and rebuilt turned the same way: the worker's part is in the same (work)
coordinates as the caller's, and ``setup_part`` with the same job leaves it as it is
(a plain part of the turned shape would be turned a second time).

When the part's adjacency is computed, the blob carries it as plain numbers
(:func:`adjacency_record`: each shared edge's index in the part's edge map and its
classification) and the rebuilt part takes it with its own edge objects instead of
classifying every edge again (seconds on a large part, in every worker). It is the
adjacency of the part given (turned, for a setup), taken by the part rebuilt (turned
the same way); where the rebuilt part's edges do not agree with the record (other
indices or faces), it is dropped and the part classifies as usual.
"""

from __future__ import annotations

import io

from OCP.BinTools import BinTools, BinTools_FormatVersion
from OCP.TopoDS import TopoDS_Shape

from .part import Part, SharedEdge
from .setup import Setup, setup_in, setup_part


def part_blob(part: Part) -> tuple:
    """(BRep bytes, source, tolerances, flip_material, warnings, setup dict or None,
    adjacency record or None): the arguments of :func:`part_from_blob`; all of them
    pickle."""
    setup = setup_in(part)
    made_from = part if setup is None else part.original
    stream = io.BytesIO()
    BinTools.Write_s(made_from.given_shape, stream, False, False,
                     BinTools_FormatVersion.BinTools_FormatVersion_CURRENT)
    return (stream.getvalue(), made_from.source, made_from.tol, made_from.flip_material,
            list(made_from.warnings), None if setup is None else setup.to_dict(),
            adjacency_record(part))


def part_from_blob(blob: bytes, source: str, tol, flip_material: bool,
                   warnings: list | None = None, setup: dict | None = None,
                   adjacency: tuple | None = None) -> Part:
    """The :class:`Part` of :func:`part_blob`'s answer (turned into ``setup`` if given),
    with the ``adjacency`` record's classification where it fits (module doc)."""
    shape = TopoDS_Shape()
    BinTools.Read_s(shape, io.BytesIO(blob))
    part = Part(shape, source=source, tol=tol, flip_material=flip_material)
    part.warnings = list(warnings or [])
    if setup is not None:
        part = setup_part(part, Setup.from_dict(setup))
    if adjacency is not None:
        take_adjacency_record(part, adjacency)
    return part


def adjacency_record(part: Part) -> tuple | None:
    """``part``'s adjacency as plain numbers, None where it is not computed: (edges in
    ``part.edge_map()``, rows), a row per shared edge in adjacency order: (its 1-based
    index in the edge map, faces, edge_class, angles_deg, points, length, closed, start,
    end, start_tangent, end_tangent)."""
    if not part.adjacency_known:
        return None
    emap = part.edge_map()
    rows = [(emap.FindIndex(e.edge), e.faces, e.edge_class, e.angles_deg, e.points,
             e.length, e.closed, e.start, e.end, e.start_tangent, e.end_tangent)
            for edges in part.adjacency.values() for e in edges]
    return emap.Extent(), rows


def take_adjacency_record(part: Part, record: tuple) -> bool:
    """Give ``part`` the adjacency of :func:`adjacency_record` of a part built the same
    way, with ``part``'s own edges; True if taken. Not taken (False: the part classifies
    as usual) unless ``part``'s edge map has as many edges and its shared edges are the
    record's, at the same indices between the same faces."""
    extent, rows = record
    emap = part.edge_map()
    edges = {k: (edge, tuple(numbers)) for k, edge, numbers in part.shared_edge_indices()}
    if emap.Extent() != extent or sorted((k, faces) for k, (_, faces) in edges.items()) \
            != sorted((row[0], tuple(row[1])) for row in rows):
        return False
    adjacency: dict[tuple[int, int], list[SharedEdge]] = {}
    for k, faces, *fields in rows:
        adjacency.setdefault(faces, []).append(SharedEdge(faces, edges[k][0], *fields))
    part.take_adjacency(adjacency)
    return True
