"""The picture of docs/simulate.md's stock mesh: a box cut by a ball from above along a
polyline and by a tool along +X into its side (a slot under the stock), meshed from the three
grids' dexels (:func:`cadcnc.simulation.stock_mesh.dexel_mesh`), shaded with matplotlib.

    python -m benchmarks.simulation.stock_mesh_picture [-o docs/img/simulate_stock_mesh.png]
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from cadcnc.simulation.stock import cut_stock  # noqa: E402
from cadcnc.simulation.stock_mesh import dexel_mesh  # noqa: E402
from cadcnc.simulation.tool_moves import Run  # noqa: E402

LO, HI = np.array([0.0, 0.0, 0.0]), np.array([20.0, 15.0, 8.0])
PATH = [(-1, 3, 7.5), (8, 4, 6.2), (14, 10, 7.0), (21, 12, 5.5)]
SIDE = [(18.5, 2.0, 4.0), (18.0, 13.0, 3.5)]


def stock_mesh(res: float) -> tuple[np.ndarray, np.ndarray]:
    """The example's stock mesh at ``res`` mm."""
    def run(points, radius, axis, shank):
        pts = np.asarray(points, float)
        return Run(pts, np.zeros(len(pts) - 1, bool), radius, np.asarray(axis, float), 0.0,
                   shank)
    stock = cut_stock(LO, HI, res, [run(PATH, 2.0, (0, 0, 1), 0.0),
                                    run(SIDE, 1.5, (1, 0, 0), 6.0)])
    return dexel_mesh(stock)


def picture(verts: np.ndarray, tris: np.ndarray, title: str) -> plt.Figure:
    """The mesh shaded by the angle of its faces to a light from above the viewer."""
    tri = verts[tris]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-30  # (degenerate faces: dark)
    light = np.array([0.25, -0.5, 0.83]) / np.linalg.norm([0.25, -0.5, 0.83])
    shade = 0.2 + 0.8 * np.clip(normal @ light, 0, 1)
    fig = plt.figure(figsize=(8, 6))
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(Poly3DCollection(tri, facecolors=plt.cm.Greys_r(shade * 0.85),
                                         edgecolor="none", antialiased=False))
    ax.set_xlim(LO[0], HI[0])
    ax.set_ylim(LO[1], HI[1])
    ax.set_zlim(LO[2], HI[2])
    ax.set_box_aspect(HI - LO)
    ax.view_init(elev=28, azim=-35)
    ax.set_xlabel("X mm")
    ax.set_ylabel("Y mm")
    ax.set_zlabel("Z mm")
    ax.set_title(title, fontsize=10)
    return fig


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", default="simulate_stock_mesh.png")
    ap.add_argument("--resolution", type=float, default=0.2)
    args = ap.parse_args(argv)
    verts, tris = stock_mesh(args.resolution)
    fig = picture(verts, tris, f"stock mesh from the X, Y and Z dexels, {args.resolution} mm "
                  f"({len(tris)} triangles): the side slot's overhang stays")
    fig.savefig(args.o, dpi=110, bbox_inches="tight")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
