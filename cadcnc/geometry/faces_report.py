"""A part's faces, neighbours and pairs as plain data (``cadcnc faces --json``)."""

from __future__ import annotations

from .part import CONCAVE, Part


def _angle_range(edges) -> list[float]:
    lo = min(e.angle_range_deg[0] for e in edges)
    hi = max(e.angle_range_deg[1] for e in edges)
    return [round(lo, 4), round(hi, 4)]


def faces_report(part: Part) -> dict:
    """{"file", "n_faces", "faces": [...], "pairs": [...], "concave_pairs", "warnings"}
    (what OCCT's reader printed); areas mm^2,
    angles deg (material-side dihedral: < 180 convex, > 180 concave), lengths mm."""
    out = {"file": str(part.source), "n_faces": len(part), "faces": [], "pairs": []}
    for f in part.faces:
        nbs = [{"face": m, "class": part.pair_class(f.number, m),
                "angle_deg": _angle_range(edges), "edges": len(edges)}
               for m, edges in sorted(part.neighbours(f.number).items())]
        out["faces"].append({"number": f.number, "kind": f.kind,
                             "area_mm2": round(f.area(), 6), "reversed": bool(f.reversed),
                             "neighbours": nbs})
    for (i, j), edges in part.adjacency.items():
        out["pairs"].append({"faces": [i, j], "class": part.pair_class(i, j), "edges": [
            {"class": e.edge_class, "angle_deg": _angle_range([e]),
             "length_mm": round(e.length, 6), "closed": bool(e.closed)} for e in edges]})
    out["concave_pairs"] = [list(p) for p in part.concave_pairs()]
    out["material"] = material_report(part)
    out["warnings"] = list(part.warnings)
    return out


def material_report(part: Part) -> dict:
    """{"rule", "flipped", ["shells", "sewing"]}: which rule put the material where
    (docs/notes/surface_models.md); for a surface model each shell's faces and rule, and the
    sewing tolerance, largest edge tolerance after sewing (mm) and free edges."""
    out = {"rule": part.material_rule, "flipped": part.flip_material}
    model = part.surface_model
    if model is not None:
        out["shells"] = [s.to_dict() for s in model.shells]
        out["sewing"] = {"tolerance_mm": model.sewn.tolerance,
                         "max_edge_tolerance_mm": model.sewn.edge_tolerance,
                         "free_edges": model.sewn.free_edges}
    return out


def concave_edges(report: dict):
    """(i, j, k, edge) for each concave edge k (1-based) of each concave pair."""
    for pair in report["pairs"]:
        if pair["class"] == CONCAVE:
            for k, e in enumerate(pair["edges"], 1):
                yield pair["faces"][0], pair["faces"][1], k, e
