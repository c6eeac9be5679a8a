"""Pictures of a stock simulation: the part coloured by the material left, gouges standing
out; the simulated stock as a mesh.

PNG (matplotlib): two views of the part (isometric and from above), each face triangle
coloured by the material left at its nearest sample (viridis, 0 to the 99th percentile,
a colour bar in mm), gouges as large magenta markers with their depth. GLB (trimesh): the
part with vertex colours, the stock mesh (grey) and the gouges (magenta spheres). STL: the
stock mesh. The simulation hands over plain arrays: sample points (n, 3) mm and material
left (n,) mm, gouge points (g, 3) and depths (g,), the stock mesh (vertices, triangles).
"""

from __future__ import annotations

import io

import numpy as np

from ..geometry.mesh import tessellate

GOUGE_COLOUR = (1.0, 0.0, 1.0)
STOCK_COLOUR = (0.62, 0.62, 0.66, 0.45)
SUFFIXES = (".json", ".png", ".glb", ".stl")


def coloured_part(part, points, left, tolerance: float = 0.05):
    """(vertices (n, 3), triangles (m, 3), left at each vertex (n,) mm) of the part's
    display mesh, each vertex given its nearest sample's material left."""
    from scipy.spatial import cKDTree  # ~0.3 s to import: only pictures need it

    verts, tris = tessellate(part.shape, tolerance)
    if len(points) == 0:
        return verts, tris, np.zeros(len(verts))
    _, near = cKDTree(points).query(verts)
    return verts, tris, np.clip(np.asarray(left)[near], 0.0, None)


UNCUT = 0.5   # mm: material left above this is taken as never cut (grey, over the scale)


def scale_of(left, threshold: float = 0.0) -> float:
    """The colour bar's top (mm): the 99th percentile of the material left where it was
    cut (below ``UNCUT``), at least twice ``threshold`` and 1 um; above it: grey."""
    cut = np.asarray(left)[np.asarray(left) < UNCUT]
    return max(float(np.percentile(cut, 99)) if len(cut) else 0.0, 2 * threshold, 1e-3)  # mm: 1 um


def png_bytes(part, points, left, gouges: list[dict], threshold: float = 0.0,
              title: str = "", dpi: int = 110) -> bytes:
    """The PNG (module doc); ``gouges``: the report's [{"at", "depth_mm", ...}]."""
    import matplotlib  # ~0.5 s to import: only pictures need it
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    verts, tris, vleft = coloured_part(part, points, left)
    top = scale_of(vleft, threshold)
    cmap = plt.get_cmap("viridis").with_extremes(over=(0.78, 0.78, 0.78))
    colours = cmap(plt.Normalize(0, top)(vleft[tris].mean(axis=1)))
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    fig = plt.figure(figsize=(13, 6.2))
    for i, (elev, azim, name) in enumerate(((32, -58, "isometric"), (89.9, -90, "from above"))):
        ax = fig.add_subplot(1, 2, i + 1, projection="3d", computed_zorder=False)
        ax.add_collection3d(Poly3DCollection(verts[tris], facecolors=colours,
                                             edgecolors="none", linewidths=0, zorder=1))
        for g in gouges[:20]:
            x, y, z = g["at"]
            ax.scatter([x], [y], [z], s=220, c=[GOUGE_COLOUR], marker="X",
                       edgecolors="black", linewidths=1.0, depthshade=False, zorder=10)
            ax.text(x, y, z, f"  {g['depth_mm'] * 1000:.0f} um", color="black",
                    fontsize=9, fontweight="bold", zorder=11)
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_zlim(lo[2], hi[2])
        ax.set_box_aspect(np.maximum(hi - lo, 1e-6))  # mm: a flat box still has an aspect
        ax.view_init(elev=elev, azim=azim)
        ax.set_xlabel("X mm")
        ax.set_ylabel("Y mm")
        ax.set_title(name)
        if i == 1:
            ax.set_zticks([])
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, top))
    bar = fig.colorbar(sm, ax=fig.axes, shrink=0.75, pad=0.02, extend="max")
    bar.set_label(f"material left (mm); grey: more than {top:.3g} mm (not cut)")
    deepest = max((g["depth_mm"] for g in gouges), default=0.0)
    note = (f"{len(gouges)} gouge(s), deepest {deepest:.4f} mm (magenta X)"
            if gouges else "no gouge")
    fig.suptitle(f"{title}\n{note}", fontsize=11)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return buf.getvalue()


def glb_bytes(part, points, left, gouge_points, stock_mesh, threshold: float = 0.0) -> bytes:
    """The GLB (module doc)."""
    import matplotlib  # ~0.5 s to import: only pictures need it
    import trimesh  # ~0.5 s to import: only pictures need it

    verts, tris, vleft = coloured_part(part, points, left)
    top = scale_of(vleft, threshold)
    rgba = matplotlib.colormaps["viridis"](np.clip(vleft / top, 0, 1))
    rgba[vleft > top] = (0.78, 0.78, 0.78, 1.0)
    scene = trimesh.Scene()
    scene.add_geometry(trimesh.Trimesh(verts, tris, vertex_colors=(rgba * 255).astype(
        np.uint8), process=False), node_name="part")
    sv, st = stock_mesh
    if len(st):
        colour = (np.array(STOCK_COLOUR) * 255).astype(np.uint8)
        scene.add_geometry(trimesh.Trimesh(sv, st, face_colors=np.tile(colour, (len(st), 1)),
                                           process=False), node_name="stock")
    for i, p in enumerate(np.asarray(gouge_points)[:200]):
        ball = trimesh.creation.icosphere(subdivisions=1, radius=0.3)
        ball.apply_translation(p)
        ball.visual.face_colors = (np.array([*GOUGE_COLOUR, 1.0]) * 255).astype(np.uint8)
        scene.add_geometry(ball, node_name=f"gouge_{i + 1}")
    return scene.export(file_type="glb")


def stl_bytes(stock_mesh) -> bytes:
    """The stock mesh as binary STL."""
    import trimesh  # ~0.5 s to import: only pictures need it

    return trimesh.Trimesh(*stock_mesh, process=False).export(file_type="stl")
