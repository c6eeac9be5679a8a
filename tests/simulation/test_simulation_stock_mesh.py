"""The stock mesh from the three grids' dexels: closed, facing out, and holding the volume
that an independent boolean reference (manifold3d) holds, undercuts included."""

from __future__ import annotations

import io

import numpy as np
import pytest

from cadcnc.io.simulation_plot import stl_bytes
from cadcnc.simulation.stock import cut_stock
from cadcnc.simulation.stock_mesh import dexel_mesh, mesh_note, stride_for
from cadcnc.simulation.tool_moves import Run

trimesh = pytest.importorskip("trimesh")
manifold3d = pytest.importorskip("manifold3d")

LO, HI = np.array([0.0, 0.0, 0.0]), np.array([20.0, 15.0, 8.0])
SEGMENTS = 96


def closed_mesh(stock, max_side: int = 400):
    verts, tris = dexel_mesh(stock, max_side)
    mesh = trimesh.Trimesh(verts, tris)
    assert mesh.is_watertight and mesh.is_winding_consistent
    return mesh


def chamfer_loss(size, res: float) -> float:
    """What the mesh of an uncut box lacks at most: along each of its 12 edges a triangle
    of legs res / 2 (the outer nodes lie half a cell inside)."""
    return 4 * float(np.sum(size)) * res * res / 8


def run(points, radius, axis=(0.0, 0.0, 1.0), shank=0.0):
    pts = np.asarray(points, float)
    return Run(pts, np.zeros(len(pts) - 1, bool), radius, np.asarray(axis, float), 0.0, shank)


def reference_volume(moves: list[tuple[np.ndarray, np.ndarray, float, np.ndarray, float]]):
    """The box minus, per move, the hull of the balls at both ends of the tool's axis
    segment at both ends of the move (manifold3d; its own spheres, SEGMENTS around): its
    volume and area."""
    m = manifold3d.Manifold
    solid = m.cube(tuple(HI - LO)).translate(tuple(LO))
    for p0, p1, r, axis, length in moves:
        ends = [p0, p1, p0 + length * axis, p1 + length * axis]
        solid = solid - m.batch_hull([m.sphere(r, SEGMENTS).translate(tuple(c)) for c in ends])
    mesh = solid.to_mesh()
    ref = trimesh.Trimesh(np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts))
    return ref.volume, ref.area


def test_an_uncut_box_is_closed_and_holds_the_box():
    res = 0.25
    stock = cut_stock(LO, HI, res, [run([(-9, -9, -9), (-8, -9, -9)], 0.5)], jobs=1)
    mesh = closed_mesh(stock)
    loss = float(np.prod(HI - LO)) - mesh.volume
    assert 0 <= loss <= chamfer_loss(HI - LO, res)
    assert np.allclose(mesh.bounds, [LO, HI])          # the box's faces are its crossings
    stl = trimesh.load(io.BytesIO(stl_bytes(dexel_mesh(stock))), file_type="stl")
    assert stl.is_watertight and stl.volume == pytest.approx(mesh.volume, rel=1e-6)  # float32
    coarse = closed_mesh(stock, max_side=20)           # every 4th ray
    assert stride_for(stock, 20) == 4
    assert mesh_note(stock, 20).startswith("stock mesh: one ray in 4, 1 mm") and not mesh_note(stock)
    assert 0 <= float(np.prod(HI - LO)) - coarse.volume <= chamfer_loss(HI - LO, 4 * res)


@pytest.mark.parametrize("res", [0.25, 0.1])
def test_ball_and_side_slot_match_the_boolean_reference(res):
    """A ball along a polyline from above, and a tool along +X entering the +X side at mid
    height (an undercut: the stock above its slot stays, which no height field holds)."""
    path = np.array([(-1, 3, 7.5), (8, 4, 6.2), (14, 10, 7.0), (21, 12, 5.5)])
    side = np.array([(18.5, 2.0, 4.0), (18.0, 13.0, 3.5)])
    runs = [run(path, 2.0), run(side, 1.5, axis=(1.0, 0.0, 0.0), shank=6.0)]
    stock = cut_stock(LO, HI, res, runs, jobs=1)
    mesh = closed_mesh(stock)
    moves = [(a, b, 2.0, np.array([0.0, 0.0, 1.0]), 0.0) for a, b in zip(path[:-1], path[1:])]
    moves.append((side[0], side[1], 1.5, np.array([1.0, 0.0, 0.0]), 6.0))
    volume, area = reference_volume(moves)
    # the mesh's triangles stand within res / 8 of the dexel surface on average (flat
    # between exact crossings; chamfers of legs res / 2 along sharp edges); the reference's
    # polyhedral balls hold a little more (their sagitta, far below that)
    assert abs(mesh.volume - volume) <= area * res / 8
    # a vertical line through the slot (off the lattice's symmetric points) meets the
    # bottom, the slot's floor and ceiling (the shank's radius about its axis) and the top
    x, y = 19.03, 7.46
    axis_z = side[0, 2] + (side[1, 2] - side[0, 2]) * (y - side[0, 1]) / (side[1, 1] - side[0, 1])
    z = np.sort(vertical_hits(mesh, x, y))
    assert len(z) == 4
    assert np.abs(z - [LO[2], axis_z - 1.5, axis_z + 1.5, HI[2]]).max() <= res


def vertical_hits(mesh, x: float, y: float) -> np.ndarray:
    """The heights where the vertical line through (x, y) meets the mesh's triangles."""
    a, b, c = (mesh.vertices[mesh.faces][:, i] for i in range(3))
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):     # vertical triangles: no hit
        w1 = ((x - a[:, 0]) * (c[:, 1] - a[:, 1]) - (y - a[:, 1]) * (c[:, 0] - a[:, 0])) / area
        w2 = ((b[:, 0] - a[:, 0]) * (y - a[:, 1]) - (b[:, 1] - a[:, 1]) * (x - a[:, 0])) / area
        on = np.isfinite(w1) & np.isfinite(w2) & (w1 >= 0) & (w2 >= 0) & (w1 + w2 <= 1)
    a, b, c, w1, w2 = a[on], b[on], c[on], w1[on], w2[on]
    return a[:, 2] + w1 * (b[:, 2] - a[:, 2]) + w2 * (c[:, 2] - a[:, 2])
