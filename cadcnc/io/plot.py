"""Pictures of a toolpath: a matplotlib PNG and a trimesh glTF (.glb) scene.

PNG: left, the two faces near the path (tessellated), the cutter-centre path and both
contact lines; right, the deviation along the path: each cutter centre's distance to
each face's surface (OCCT projection) minus that face's offset, in micrometres over arc
length, beside the paper's eq. 16 bound drawn as an over-cut limit. GLB: the part mesh
(the pair's faces coloured), the path and the contact lines as line strips.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from ..core.errors import OutputError
from ..geometry.mesh import tessellate
from .output_set import write_one

FACE_COLOURS = ((0.35, 0.55, 0.85), (0.85, 0.55, 0.30))
PATH_COLOUR = (0.80, 0.10, 0.10)


def _crop(v, t, lo, hi):
    """Triangles whose centroid lies in the box lo..hi."""
    c = v[t].mean(axis=1)
    return t[np.all((c >= lo) & (c <= hi), axis=1)]


def figure(path, part, title: str = ""):
    """A matplotlib Figure of ``path`` on ``part`` (faces ``path.faces``)."""
    import matplotlib  # ~0.5 s with pyplot: only pictures need it

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(12, 5.5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    pts = path.points
    span = max(float(np.ptp(pts, axis=0).max()), 1e-6)   # mm: a point still has a scale
    margin = max(0.25 * span, 4 * max(path.offsets))
    lo, hi = pts.min(axis=0) - margin, pts.max(axis=0) + margin
    for k, number in enumerate(path.faces):
        if number is None or part is None:
            continue
        v, t = tessellate(part.face(number).topods, tolerance=max(span / 400, 0.01))
        t = _crop(v, t, lo, hi)
        if len(t):
            ax.plot_trisurf(v[:, 0], v[:, 1], v[:, 2], triangles=t, color=FACE_COLOURS[k],
                            alpha=0.35, linewidth=0, shade=True)
    ax.plot(*pts.T, color=PATH_COLOUR, lw=1.6, label="cutter centre")
    for k in (0, 1):
        ax.plot(*path.contacts[:, k].T, color=FACE_COLOURS[k], lw=1.0, ls="--",
                label=f"contact on face {path.faces[k]}")
    ax.scatter(*pts[0], color="k", s=12)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - half, c + half)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(title or f"faces {path.faces[0]} and {path.faces[1]}", fontsize=10)

    ax2 = fig.add_subplot(1, 2, 2)
    s = np.cumsum(path.steps)
    idx = np.unique(np.linspace(0, len(path) - 1, min(len(path), 1500)).astype(int))
    for k, number in enumerate(path.faces):
        if part is None or number is None:
            break
        dev = deviation(path, part.face(number), k, idx)
        ax2.plot(s[idx], dev * 1e3, color=FACE_COLOURS[k], lw=1.2,
                 label=f"face {number}: distance - offset")
        if path.bounds is not None:
            bound = np.where(np.isfinite(path.bounds[k].eq16), path.bounds[k].eq16, np.nan)
            ax2.plot(s, -bound * 1e3, color=FACE_COLOURS[k], lw=0.8, ls=":",
                     label=f"face {number}: eq. 16 over-cut bound")
    ax2.axhline(0.0, color="k", lw=0.5)
    ax2.set_ylabel("deviation (um): > 0 material left, < 0 over-cut")
    ax2.set_xlabel("arc length along the path (mm)")
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize=8)
    ax2.set_title(f"{len(path)} points, {path.length:.3f} mm, stop: {path.stop_reason}",
                  fontsize=10)
    fig.tight_layout()
    return fig


def deviation(path, surface, k: int, idx=None) -> np.ndarray:
    """Signed distance (mm) of cutter centres to ``surface`` minus the offset of side k.

    OCCT's projection onto the face's surface (within its parameter box): > 0 leaves
    material, < 0 cuts into the surface. ``idx`` selects the points (default all).
    """
    idx = np.arange(len(path)) if idx is None else idx
    return np.array([surface.project(path.points[i])[2] for i in idx]) - path.offsets[k]


def png_bytes(path, part, title: str = "", dpi: int = 110) -> bytes:
    import matplotlib.pyplot as plt

    fig = figure(path, part, title)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return buf.getvalue()


def scene(path, part):
    """A trimesh Scene: part faces as meshes (the pair coloured), path and contact lines."""
    import trimesh  # ~0.5 s to import: only .glb scenes need it

    sc = trimesh.Scene()
    if part is not None:
        pair = {n: FACE_COLOURS[k] for k, n in enumerate(path.faces) if n is not None}
        for face in part.faces:
            v, t = tessellate(face.topods, tolerance=0.05)
            if not len(t):
                continue
            rgb = pair.get(face.number, (0.75, 0.75, 0.75))
            mesh = trimesh.Trimesh(v, t, process=False)
            mesh.visual.face_colors = [int(255 * c) for c in rgb] + [255]
            sc.add_geometry(mesh, geom_name=f"face{face.number}")
    lines = [("path", path.points, PATH_COLOUR)] + [
        (f"contact{k + 1}", path.contacts[:, k], FACE_COLOURS[k]) for k in (0, 1)]
    for name, pts, rgb in lines:
        line = trimesh.load_path(np.asarray(pts, dtype=float))
        line.colors = np.tile([int(255 * c) for c in rgb] + [255], (len(line.entities), 1))
        sc.add_geometry(line, geom_name=name)
    return sc


def glb_bytes(path, part) -> bytes:
    return scene(path, part).export(file_type="glb")


PICTURE_SUFFIXES = (".png", ".glb")


def picture_bytes(path, part, out, title: str = "") -> bytes:
    """The picture of ``path`` on ``part`` in the format of ``out``'s suffix: .png
    (matplotlib) or .glb (trimesh scene)."""
    suffix = Path(out).suffix.lower()
    if suffix == ".png":
        return png_bytes(path, part, title)
    if suffix == ".glb":
        return glb_bytes(path, part)
    raise OutputError(f"{out}: unknown picture format {suffix or '(no suffix)'!r}; "
                      "use .png or .glb")


def write_picture(path, part, out, title: str = "") -> None:
    """Write ``out`` by suffix (see :func:`picture_bytes`), atomically."""
    write_one(out, picture_bytes(path, part, out, title), PICTURE_SUFFIXES)
