"""Pictures of a program: the part, each cut in its own colour, the links dashed.

PNG (matplotlib): the part tessellated in translucent grey, every cut segment as a line in
a colour of its own (numbered at its start), link moves as dashed grey lines, and the
program's totals in the title. GLB (trimesh): the part's faces, the cut lines coloured the
same way and the links grey, so a user sees at a glance what will be cut and how the tool
travels between cuts.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from ..core.errors import OutputError
from ..core.job import axis_name
from ..geometry.mesh import tessellate
from ..geometry.setup import job_setup, original_part
from ..program.program import Program
from ..program.transform import in_part_coordinates
from .output_set import write_one

LINK_COLOUR = (0.45, 0.45, 0.45)
PART_COLOUR = (0.75, 0.75, 0.78)


def cut_colours(n: int) -> list[tuple[float, float, float]]:
    """``n`` distinct colours (tab10, then hsv), one per cut."""
    import matplotlib  # ~0.5 s: only pictures need it

    cmap = matplotlib.colormaps["tab10" if n <= 10 else "hsv"]
    return [tuple(cmap(k if n <= 10 else k / n)[:3]) for k in range(n)]


def _title(program: Program, title: str) -> str:
    t = program.totals()
    head = f"{title}: " if title else ""
    state = "complete" if program.complete else "partial"
    return (f"{head}{t['cuts']} cuts, {t['cut_length_mm']:.1f} mm cut, "
            f"{t['link_length_mm']:.1f} mm links, {t['skipped']} skipped, {state}")


def program_figure(program: Program, part, title: str = "", axis=None):
    """A matplotlib Figure of ``program`` over ``part`` (None: the moves alone), in part
    coordinates; ``axis`` (3,): the tool axis, drawn as an arrow above the moves."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(9, 7.5))
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    moves = program.all_moves()
    lo, hi = moves.min(axis=0), moves.max(axis=0)
    if part is not None:
        v, t = tessellate(part.shape, tolerance=max(float(np.ptp(moves, axis=0).max()) / 300,
                                                    0.02))
        if len(t):
            ax.plot_trisurf(v[:, 0], v[:, 1], v[:, 2], triangles=t, color=PART_COLOUR,
                            alpha=0.25, linewidth=0, shade=True)
            lo, hi = np.minimum(lo, v.min(axis=0)), np.maximum(hi, v.max(axis=0))
    colours = cut_colours(len(program.cuts))
    k = 0
    for seg in program.segments:
        if seg.kind == "cut":
            ax.plot(*seg.points.T, color=colours[k], lw=2.0)
            ax.text(*seg.points[0], str(k + 1), color=colours[k], fontsize=8)
            k += 1
        else:
            ax.plot(*seg.points.T, color=LINK_COLOUR, lw=0.8, ls="--")
    centre, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-3)  # mm: not 0 for a point
    if axis is not None:   # from the centre of the box out along the axis, named
        tip = centre + np.asarray(axis) * half * 0.95
        ax.quiver(*centre, *(tip - centre), color="crimson", lw=2.0, arrow_length_ratio=0.15)
        ax.text(*tip, f"tool axis {axis_name(tuple(axis))}", color="crimson", fontsize=9)
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - half, c + half)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.set_title(_title(program, title), fontsize=10)
    fig.tight_layout()
    return fig


def program_scene(program: Program, part, axis=None):
    """A trimesh Scene: the part's faces, cut lines coloured one per cut, links grey, in
    part coordinates; ``axis`` (3,): the tool axis as a red line named ``tool_axis``."""
    import trimesh  # ~0.5 s to import: only .glb scenes need it

    sc = trimesh.Scene()
    if part is not None:
        for face in part.faces:
            v, t = tessellate(face.topods, tolerance=0.05)
            if len(t):
                mesh = trimesh.Trimesh(v, t, process=False)
                mesh.visual.face_colors = [int(255 * c) for c in PART_COLOUR] + [255]
                sc.add_geometry(mesh, geom_name=f"face{face.number}")
    colours = iter(cut_colours(len(program.cuts)))
    for k, seg in enumerate(program.segments, 1):
        rgb = next(colours) if seg.kind == "cut" else LINK_COLOUR
        line = trimesh.load_path(np.asarray(seg.points, dtype=float))
        line.colors = np.tile([int(255 * c) for c in rgb] + [255], (len(line.entities), 1))
        sc.add_geometry(line, geom_name=f"{seg.kind}{k}")
    if axis is not None:
        moves = program.all_moves()
        centre, size = moves.mean(axis=0), float(np.ptp(moves, axis=0).max()) or 1.0
        line = trimesh.load_path(np.array([centre, centre + np.asarray(axis) * size]))
        line.colors = np.tile([220, 20, 60, 255], (len(line.entities), 1))
        sc.add_geometry(line, geom_name=f"tool_axis {axis_name(tuple(axis))}")
    return sc


def program_picture_bytes(program: Program, part, out, title: str = "") -> bytes:
    """The picture of ``program`` in the format of ``out``'s suffix (.png or .glb), in part
    coordinates; a program of another tool axis than +Z shows and names its axis."""
    suffix = Path(out).suffix.lower()
    setup, axis = job_setup(program.job, part), None
    if setup is not None:
        program, part, axis = in_part_coordinates(program, setup), original_part(part), setup.axis
        title = title if "tool axis" in title else f"{title} (tool axis {setup.name})".strip()
    if suffix == ".png":
        import matplotlib.pyplot as plt

        fig = program_figure(program, part, title, axis)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110)
        plt.close(fig)
        return buf.getvalue()
    if suffix == ".glb":
        return program_scene(program, part, axis).export(file_type="glb")
    raise OutputError(f"{out}: unknown picture format {suffix or '(no suffix)'!r}; "
                      "use .png or .glb")


def write_program_picture(program: Program, part, out, title: str = "") -> None:
    """Write ``out`` by suffix (see :func:`program_picture_bytes`), atomically."""
    write_one(out, program_picture_bytes(program, part, out, title), (".png", ".glb"))
