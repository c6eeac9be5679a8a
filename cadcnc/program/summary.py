"""The text summary of a program, for every operation: what was asked, every cut (or their
count), the links, what was skipped and why, the notes, the totals and complete or partial
(why). ``Program.summary()`` returns it; the CLI prints it."""

from __future__ import annotations

from ..core.units import format_duration

CUT_LINES = 12
"""Programs with more cuts than this list them counted, not one by one."""
SKIPPED_LINES = 12
"""Skipped entries listed one by one at most (the rest counted by reason)."""


def xyz(p) -> str:
    """A point as ``(x, y, z) mm`` with 4 decimals."""
    return "(" + ", ".join(f"{float(v):.4f}" for v in p) + ") mm"


def skipped_counts(program) -> str:
    """Skipped corners, stretches or passes counted by reason: "2 no_fit, 1 tangent"."""
    counts: dict[str, int] = {}
    for s in program.skipped:
        counts[s.reason] = counts.get(s.reason, 0) + 1
    return ", ".join(f"{n} {r}" for r, n in sorted(counts.items()))


def _operation(job) -> str:
    return job.operation.describe()   # every operation record's own words


def _cut_lines(k: int, seg) -> list[str]:
    p = seg.path
    where = ", ".join(w for w in (f"edge {seg.edge}" if seg.edge else "",
                                  f"stretch {seg.stretch}" if seg.stretch else "") if w)
    state = "complete" if seg.complete else "partial: " + p.partial_reason
    return [f"  cut {k}: faces {p.faces[0]} {p.faces[1]}" + (f", {where}" if where else "")
            + f": {p.length:.4f} mm, {len(p)} points, {p.duration:.4f} s",
            f"      stop {p.stop_reason}: {p.stop_detail} ({state})",
            f"      from {xyz(p.points[0])} to {xyz(p.points[-1])}",
            f"      predicted {p.worst_predicted_mm:.3g} mm worst steady-state error (eq. 16)",
            *([f"      accuracy   {p.accuracy_note}"] if p.accuracy_note else [])]


def program_summary(program, part_name: str = "") -> str:
    """The summary of ``program`` (see the module doc); ``part_name`` heads it."""
    job = program.job
    lines = [(f"{part_name}: " if part_name else "") + _operation(job),
             f"  ball R {job.tool.radius:g} mm, allowance {job.tool.allowance:g} mm, feed "
             f"{job.feed:g} mm/min, period {format_duration(job.period)} "
             f"(step {job.step:.6g} mm)"]
    cuts = program.cuts
    if len(cuts) <= CUT_LINES:
        for k, seg in enumerate(cuts, 1):
            lines += _cut_lines(k, seg)
    else:
        stops: dict[str, int] = {}
        for seg in cuts:
            stops[seg.path.stop_reason] = stops.get(seg.path.stop_reason, 0) + 1
        lines.append(f"  cuts       {len(cuts)}, stopped by " + ", ".join(
            f"{r} {n}" for r, n in sorted(stops.items())))
    t = program.totals()
    lifts = sum(1 for s in program.links if s.rapid.any())
    lines.append(f"  links      {t['links']} ({lifts} with a lift), "
                 f"{t['link_length_mm']:.3f} mm (retract, rapid, plunge)")
    for s in program.skipped[:SKIPPED_LINES]:
        edge = f" edge {s.edge}" if s.edge else ""
        faces = " ".join(str(f) for f in s.faces)
        lines.append(f"  skipped    faces {faces}{edge}: {s.reason}"
                     + (f": {s.detail}" if s.detail else ""))
    if len(program.skipped) > SKIPPED_LINES:
        lines.append(f"  skipped    {len(program.skipped)} in all: {skipped_counts(program)}")
    lines += [f"  note       {n}" for n in program.notes]
    lines.append(f"  total      {t['cuts']} cut(s), {t['cut_length_mm']:.4f} mm cut, "
                 f"{program.time_at_feed:.4f} s at feed")
    state = "complete" if program.complete else "partial: " + "; ".join(
        program.partial_reasons or [s.detail for s in program.skipped
                                    if s.reason in ("stopped short", "failed")])
    lines.append(f"  result     {state}")
    return "\n".join(lines)
