"""The one-screen text summary of a toolpath, as the CLI prints it."""

from __future__ import annotations

from ..program.toolpath import Toolpath
from ..units import format_duration


def xyz(p) -> str:
    """A point as ``(x, y, z) mm`` with 4 decimals."""
    return "(" + ", ".join(f"{float(v):.4f}" for v in p) + ") mm"


def summary(path: Toolpath, part_name: str = "") -> str:
    """Faces, job, points, length, time, stop, complete or partial (and why), the steps
    the accuracy shortened (like a feed override), predicted error, start and end."""
    job = path.job
    i, j = path.faces
    note = path.accuracy_note
    return "\n".join([
        f"faces {i} and {j}" + (f" of {part_name}" if part_name else ""),
        f"  ball R {job.tool.radius:g} mm, allowance {job.tool.allowance:g} mm, feed "
        f"{job.feed:g} mm/min, period {format_duration(job.period)} (step {job.step:.6g} mm)",
        f"  points     {len(path)}",
        f"  length     {path.length:.4f} mm",
        f"  time       {path.duration:.4f} s",
        f"  stop       {path.stop_reason}: {path.stop_detail}",
        f"  result     {'complete' if path.complete else 'partial: ' + path.partial_reason}",
        *([f"  accuracy   {note}"] if note else []),
        f"  predicted  {path.worst_predicted_mm:.3g} mm worst steady-state error (eq. 16)",
        f"  start      {xyz(path.points[0])}",
        f"  end        {xyz(path.points[-1])}",
    ])

