"""A readable text table of a :class:`~cadcnc.verification.VerificationReport`."""

from __future__ import annotations

import math

FIXED_FROM_MM = 1e-3  # lengths from 1 um up print as 0.0123, smaller ones as 1.23e-05


def _mm(x) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return f"{x:.3g}" if abs(x) >= FIXED_FROM_MM or x == 0 else f"{x:.2e}"


def format_table(rep, tolerance_mm: float) -> str:
    """The report ``rep`` as text; the verdict compares its deepest gouge with ``tolerance_mm``."""
    ref = rep.reference
    lines = [
        f"faces {rep.faces[0]} & {rep.faces[1]}: {rep.n_points} points, ball R' "
        f"{rep.ball_radius:g} mm (offsets {rep.offsets[0]:g}, {rep.offsets[1]:g}), "
        f"stop: {rep.stop_reason}" + (f" ({rep.stop_detail})" if rep.stop_detail else ""),
        "",
        f"{'deviation from offset surfaces (mm)':<40}{'face ' + str(rep.faces[0]):>16}"
        f"{'face ' + str(rep.faces[1]):>16}",
    ]
    s1, s2 = rep.surfaces

    def row(label, a, b):
        lines.append(f"{label:<40}{a:>16}{b:>16}")

    row("max over-cut (gouge), trimmed face", f"{_mm(s1.max_overcut_mm)} @{s1.overcut_cycle}",
        f"{_mm(s2.max_overcut_mm)} @{s2.overcut_cycle}")
    row("max under-cut, trimmed face", f"{_mm(s1.max_undercut_mm)} @{s1.undercut_cycle}",
        f"{_mm(s2.max_undercut_mm)} @{s2.undercut_cycle}")
    row("max over-cut, untrimmed surface", _mm(s1.surface_max_overcut_mm),
        _mm(s2.surface_max_overcut_mm))
    for q in ("p50", "p95", "p99"):
        row(f"|deviation| {q}", _mm(s1.percentiles_mm[q]), _mm(s2.percentiles_mm[q]))
    row("max trimmed - untrimmed distance", _mm(s1.max_trim_gap_mm), _mm(s2.max_trim_gap_mm))
    row("unseeded checks (disagreements)", f"{s1.unseeded_checked} ({s1.unseeded_disagreements})",
        f"{s2.unseeded_checked} ({s2.unseeded_disagreements})")
    th1, th2 = rep.theory
    for eq in ("eq11", "eq12", "eq16"):
        if th1.has_bounds and th2.has_bounds:
            row(f"predicted {eq} max (cycles exceeded)",
                f"{_mm(getattr(th1, eq + '_max_mm'))} ({getattr(th1, eq + '_exceeded_abs')})",
                f"{_mm(getattr(th2, eq + '_max_mm'))} ({getattr(th2, eq + '_exceeded_abs')})")
    lines += [
        "",
        f"OCCT intersection of the offset surfaces: {ref.n_curves} curve(s), branch "
        f"{ref.branch_curves}, {ref.occt_seconds * 1e3:.1f} ms; curve residual "
        f"{_mm(ref.residual_mm)} mm",
        f"  centres to branch max {_mm(ref.points_max_mm)} mm @{ref.points_worst_cycle}; "
        f"Hausdorff (polyline, two-sided) {_mm(ref.hausdorff_mm)} mm",
        f"  curve coverage {ref.coverage:.4f} of the path's own {ref.own_span_mm:.3f} mm; "
        f"{ref.intended_coverage:.4f} of the intended {ref.span_mm:.3f} mm"
        + (f"; gaps {[(round(a, 3), round(b, 3)) for a, b in ref.gaps]}" if ref.gaps else ""),
    ]
    if ref.note:
        lines.append(f"  note: {ref.note}")
    if rep.edge_deviation_mm is not None:
        lines.append(f"  radius 0: max distance to the shared B-rep edge "
                     f"{_mm(rep.edge_deviation_mm)} mm")
    st = rep.stop
    lines.append(f"stop: {st.reason}, last contacts {st.last_contact_states}, "
                 f"remaining {st.remaining_mm:.3f} mm, consistent: {st.consistent}")
    fd = rep.feed
    lines.append(f"feed: max step error {fd.max_rel_error:.2e} (relative) @{fd.worst_cycle}"
                 + (", last shortened step excluded" if fd.excluded_last else ""))
    hits = rep.whole_part_hits
    lines.append(f"whole part ({rep.whole_part.faces_checked} faces): "
                 + ("no face hit" if not hits else f"{len(hits)} face(s) hit"))
    for h in hits:
        lines.append(f"  face {h.face}{' (followed)' if h.followed else ''}: depth "
                     f"{_mm(h.depth_mm)} mm @{h.worst_cycle}, {h.n_cycles} cycles "
                     f"{h.cycles[:4]}{'...' if len(h.cycles) > 4 else ''}")
    sw = rep.sweep
    if sw is not None:
        lines.append(f"moves ({sw.n_moves}): swept ball proven within {_mm(sw.depth_bound_mm)} "
                     f"mm, deepest measured {_mm(sw.depth_mm)} mm @{sw.worst_move}; "
                     f"{sw.distances_evaluated} distances, {sw.exact_moves} exact moves"
                     + (f"; material by {rep.whole_part.material} classifier"
                        if rep.whole_part.material else ""))
        for h in sw.hits:
            lines.append(f"  face {h.face}: depth {_mm(h.depth_mm)} mm @move {h.worst_move}, "
                         f"{h.n_moves} moves {h.moves[:4]}{'...' if len(h.moves) > 4 else ''}")
    lines.append("")
    lines.append(f"{'verdict':<12}{'measured':>12}{'limit':>12}")
    units = {"coverage": ""}
    crit = rep.criteria(tolerance_mm)
    for c in crit:
        value = f"{c.value:.4f}" if c.name == "coverage" else _mm(c.value)
        limit = f"{c.limit:g}" if c.name == "coverage" else f"{c.limit:g}"
        lines.append(f"{c.name:<12}{value:>12}{limit:>12}{units.get(c.name, ' mm')}  "
                     f"{'pass' if c.ok else 'FAIL'}" + (f"  ({c.detail})" if c.detail and not
                                                        c.ok else ""))
    failed = [c.name for c in crit if not c.ok]
    lines.append("OK" if not failed else f"FAILED: {', '.join(failed)}")
    lines.append(f"max gouge {_mm(rep.max_gouge_mm)} mm vs tolerance {tolerance_mm:g} mm: "
                 f"{'OK' if crit[0].ok else 'GOUGE'}")
    return "\n".join(lines)
