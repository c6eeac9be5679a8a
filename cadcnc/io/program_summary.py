"""The text summary of a program, as ``cadcnc path`` prints it: every cut, the links,
what was skipped and why, the notes, and complete or partial (why)."""

from __future__ import annotations

from ..program.program import Program
from ..units import format_duration
from .summary import xyz


def _cut_line(k: int, seg) -> list[str]:
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


def program_summary(program: Program, part_name: str = "") -> str:
    """Job, every cut (faces, edge, stretch, length, stop), links, skipped with reasons,
    notes, totals and the verdict "complete" or "partial: why"."""
    job = program.job
    i, j = job.operation.faces
    lines = [f"faces {i} and {j}" + (f" of {part_name}" if part_name else ""),
             f"  ball R {job.tool.radius:g} mm, allowance {job.tool.allowance:g} mm, feed "
             f"{job.feed:g} mm/min, period {format_duration(job.period)} "
             f"(step {job.step:.6g} mm)"]
    for k, seg in enumerate(program.cuts, 1):
        lines += _cut_line(k, seg)
    t = program.totals()
    lines.append(f"  links      {t['links']}, {t['link_length_mm']:.3f} mm (retract, rapid, "
                 "plunge)")
    for s in program.skipped:
        edge = f" edge {s.edge}" if s.edge else ""
        lines.append(f"  skipped    faces {s.faces[0]} {s.faces[1]}{edge}: {s.reason}"
                     + (f": {s.detail}" if s.detail else ""))
    lines += [f"  note       {n}" for n in program.notes]
    lines.append(f"  total      {t['cuts']} cut(s), {t['cut_length_mm']:.4f} mm cut, "
                 f"{program.time_at_feed:.4f} s at feed")
    state = "complete" if program.complete else "partial: " + "; ".join(
        program.partial_reasons or [s.detail for s in program.skipped])
    lines.append(f"  result     {state}")
    return "\n".join(lines)
