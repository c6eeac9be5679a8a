"""The simulated stock as a closed triangle mesh, from the dexels of all three grids.

The three grids' rays meet at one lattice of nodes: node (i, j, l) at the cell centre
``lo + ((i, j, l) + 1/2) res``, on the Z ray (i, j), the X ray (j, l) and the Y ray (l, i).
A node holds material when its Z ray's material holds it. Where an edge of the lattice joins
a node with material to one without, the surface crosses it where the ray along that edge
(X, Y or Z) says: the end of its material, exact along the ray. The mesh is then marching
cubes without a case table: each cube's crossings are linked face by face (on a face, each
exit from material, walking counter-clockwise seen from outside the cube, to the entry just
before it: the corners with material are cut off one by one where a face is ambiguous), so
two cubes sharing a face link it alike and the mesh is closed and 2-manifold. A layer of
empty nodes around the box closes it where the stock's sides are uncut: there the crossings
are the box's faces.

Side walls and undercuts come out where they are: a wall's position along X is the X rays'.
Memory stays at two layers of nodes (the mesh is built slab by slab along Z), and the
lattice uses every ``stride``-th ray so that its longest side has at most ``MAX_SIDE``
nodes (crossings stay exact along the rays used; features thinner than the stride between
two nodes may be missed).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

MESH_SUFFIXES = (".stl", ".glb")   # the outputs that hold the stock mesh
MAX_SIDE = 400        # nodes along the lattice's longest side (a coarser stride beyond)
TRIANGLES_PER_CUBE = 10   # at most: 12 crossings in loops of at least 3
# the cube's corners c = dx + 2 dy + 4 dz; its faces' corners counter-clockwise seen from
# outside (-X, +X, -Y, +Y, -Z, +Z)
FACES = np.array([[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1],
                  [4, 5, 7, 6]], np.int64)


@njit(cache=True)
def _edge(a, b):
    """The cube's edge (0..11) between corners a and b: X edges 0-3 (dy + 2 dz), Y edges
    4-7 (4 + dx + 2 dz), Z edges 8-11 (8 + dx + 2 dy)."""
    c, d = min(a, b), max(a, b) - min(a, b)
    if d == 1:
        return (c >> 1 & 1) + 2 * (c >> 2 & 1)
    if d == 2:
        return 4 + (c & 1) + 2 * (c >> 2 & 1)
    return 8 + (c & 1) + 2 * (c >> 1 & 1)


@njit(cache=True)
def _crossing(iv, cnt, r, t0, t1, entering):
    """Where ray r's material (``iv`` (rays, K, 2), ``cnt``) starts (``entering``) or ends
    first after t0, kept within [t0, t1] (offsets along the ray, mm)."""
    for i in range(cnt[r]):
        t = iv[r, i, 0] if entering else iv[r, i, 1]
        if t > t0:
            return min(max(t, t0), t1)
    return 0.5 * (t0 + t1)


@njit(cache=True)
def _offset(p, stride, res):
    """Offset (mm) from the box's low corner of padded node index p (0: the empty layer)."""
    return ((p - 1) * stride + 0.5) * res


@njit(cache=True)
def layer_occupancy(layer, nzp, np_u, np_v, stride, res, iv, cnt, nv_fine):
    """(nodes x, nodes y) bool: the material at padded layer ``layer`` of the lattice, from
    the Z grid's rays (``iv``, ``cnt``, ``nv_fine`` rays along Y); the padding is empty."""
    occ = np.zeros((np_u, np_v), np.bool_)
    if layer == 0 or layer == nzp - 1:
        return occ
    z = _offset(layer, stride, res)
    for p in range(1, np_u - 1):
        for q in range(1, np_v - 1):
            r = (p - 1) * stride * nv_fine + (q - 1) * stride
            for i in range(cnt[r]):
                if iv[r, i, 0] <= z < iv[r, i, 1]:
                    occ[p, q] = True
                    break
    return occ


@njit(cache=True)
def layer_vertices(layer, occ, stride, res, lo, xg, yg, base):
    """The crossings on the X and Y edges of padded layer ``layer`` (``occ`` its material):
    ids (nodes - 1, nodes) and (nodes, nodes - 1) (-1: none; from ``base`` on) and their
    points (m, 3) mm. ``xg``, ``yg``: (iv, cnt, rays along the grid's v) of the X, Y grids."""
    npx, npy = occ.shape
    xe = np.full((npx - 1, npy), -1, np.int64)
    ye = np.full((npx, npy - 1), -1, np.int64)
    pts = np.empty((2 * npx * npy, 3))
    n = 0
    z = _offset(layer, stride, res)
    l_fine = (layer - 1) * stride
    for p in range(npx):
        for q in range(npy):
            if p + 1 < npx and occ[p, q] != occ[p + 1, q]:     # along X: ray (y, z)
                r = (q - 1) * stride * xg[2] + l_fine
                t0, t1 = _offset(p, stride, res), _offset(p + 1, stride, res)
                pts[n, 0] = lo[0] + _crossing(xg[0], xg[1], r, t0, t1, occ[p + 1, q])
                pts[n, 1], pts[n, 2] = lo[1] + _offset(q, stride, res), lo[2] + z
                xe[p, q] = base + n
                n += 1
            if q + 1 < npy and occ[p, q] != occ[p, q + 1]:     # along Y: ray (z, x)
                r = l_fine * yg[2] + (p - 1) * stride
                t0, t1 = _offset(q, stride, res), _offset(q + 1, stride, res)
                pts[n, 1] = lo[1] + _crossing(yg[0], yg[1], r, t0, t1, occ[p, q + 1])
                pts[n, 0], pts[n, 2] = lo[0] + _offset(p, stride, res), lo[2] + z
                ye[p, q] = base + n
                n += 1
    return xe, ye, pts[:n]


@njit(cache=True)
def z_vertices(layer, occ0, occ1, stride, res, lo, zg, base):
    """The crossings on the Z edges from padded layer ``layer`` to the next: ids (nodes,
    nodes) (-1: none; from ``base`` on) and points (m, 3) mm; ``zg`` as in
    :func:`layer_vertices`, of the Z grid."""
    npx, npy = occ0.shape
    ze = np.full((npx, npy), -1, np.int64)
    pts = np.empty((npx * npy, 3))
    n = 0
    t0, t1 = _offset(layer, stride, res), _offset(layer + 1, stride, res)
    for p in range(npx):
        for q in range(npy):
            if occ0[p, q] != occ1[p, q]:
                r = (p - 1) * stride * zg[2] + (q - 1) * stride
                pts[n, 0] = lo[0] + _offset(p, stride, res)
                pts[n, 1] = lo[1] + _offset(q, stride, res)
                pts[n, 2] = lo[2] + _crossing(zg[0], zg[1], r, t0, t1, occ1[p, q])
                ze[p, q] = base + n
                n += 1
    return ze, pts[:n]


@njit(cache=True)
def _cube_ids(p, q, xe0, ye0, xe1, ye1, ze, ids):
    """The vertex ids on cube (p, q)'s 12 edges (:func:`_edge`'s order) into ``ids``."""
    for dz in range(2):
        xe, ye = (xe0, ye0) if dz == 0 else (xe1, ye1)
        for d in range(2):
            ids[d + 2 * dz] = xe[p, q + d]
            ids[4 + d + 2 * dz] = ye[p + d, q]
    for dx in range(2):
        for dy in range(2):
            ids[8 + dx + 2 * dy] = ze[p + dx, q + dy]


@njit(cache=True)
def _cube_triangles(inside, ids, tris, n):
    """Cube with material at ``inside`` (8,) corners: its loops (module doc) as fans of
    triangles facing out of the material, written into ``tris`` from row n; the new n."""
    succ = np.full(12, -1, np.int64)
    for f in range(6):
        first_exit, last_entry = -1, -1
        for s in range(4):     # each exit linked to the entry just before it
            a, b = FACES[f, s], FACES[f, (s + 1) % 4]
            if inside[a] and not inside[b]:
                if last_entry >= 0:
                    succ[_edge(a, b)] = last_entry
                elif first_exit < 0:
                    first_exit = _edge(a, b)
            elif inside[b] and not inside[a]:
                last_entry = _edge(a, b)
        if first_exit >= 0:
            succ[first_exit] = last_entry      # the entry before it, around the corner
    for e in range(12):
        if succ[e] < 0:
            continue
        a, b = e, succ[e]
        succ[e] = -1
        while b != e:          # the fan from e, reversed: the loop runs round the material
            c = succ[b]
            if c < 0:          # (a loop always closes: each crossing has one link in, one out)
                break
            succ[b] = -1
            if c != e:
                tris[n, 0], tris[n, 1], tris[n, 2] = ids[e], ids[c], ids[b]
                n += 1
            a, b = b, c
    return n


@njit(cache=True)
def slab_triangles(occ0, occ1, xe0, ye0, xe1, ye1, ze):
    """The triangles (t, 3) of the cubes between two layers (their material ``occ0``,
    ``occ1`` and their edges' vertex ids, :func:`layer_vertices`, :func:`z_vertices`)."""
    npx, npy = occ0.shape
    mixed = 0
    for p in range(npx - 1):
        for q in range(npy - 1):
            s = 0
            for d in range(4):
                s += occ0[p + (d & 1), q + (d >> 1)] + occ1[p + (d & 1), q + (d >> 1)]
            mixed += 0 < s < 8
    tris = np.empty((TRIANGLES_PER_CUBE * mixed, 3), np.int64)
    inside = np.zeros(8, np.bool_)
    ids = np.empty(12, np.int64)
    n = 0
    for p in range(npx - 1):
        for q in range(npy - 1):
            s = 0
            for c in range(8):
                o = occ0 if c < 4 else occ1
                inside[c] = o[p + (c & 1), q + (c >> 1 & 1)]
                s += inside[c]
            if s == 0 or s == 8:
                continue
            _cube_ids(p, q, xe0, ye0, xe1, ye1, ze, ids)
            n = _cube_triangles(inside, ids, tris, n)
    return tris[:n]


def stride_for(stock, max_side: int = MAX_SIDE) -> int:
    """The rays' stride that keeps the lattice's longest side within ``max_side`` nodes."""
    n = max(stock.grids[2].nu, stock.grids[2].nv, stock.grids[0].nv)
    return max(1, math.ceil(n / max_side))


def mesh_note(stock, max_side: int = MAX_SIDE) -> str:
    """The line that says the stock mesh uses every s-th ray (empty when it uses all)."""
    s = stride_for(stock, max_side)
    return "" if s == 1 else (f"stock mesh: one ray in {s}, {s * stock.res:g} mm between its "
                              f"nodes (at most {max_side} a side)")


def dexel_mesh(stock, max_side: int = MAX_SIDE) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) mm, triangles (m, 3) int, facing out) of ``stock``'s material (a
    :class:`~.stock.Stock`): closed and 2-manifold, from every ``stride_for``-th ray of
    its three grids, built two layers at a time (module doc)."""
    gx, gy, gz = stock.grids
    stride, res, lo = stride_for(stock, max_side), stock.res, np.asarray(stock.lo, float)
    n = [(gz.nu - 1) // stride + 3, (gz.nv - 1) // stride + 3, (gx.nv - 1) // stride + 3]
    xg, yg, zg = (gx.iv, gx.cnt, gx.nv), (gy.iv, gy.cnt, gy.nv), (gz.iv, gz.cnt, gz.nv)
    occ = np.zeros((n[0], n[1]), np.bool_)
    xe, ye = np.full((n[0] - 1, n[1]), -1, np.int64), np.full((n[0], n[1] - 1), -1, np.int64)
    points, triangles, count = [], [], 0
    for layer in range(n[2] - 1):
        nxt = layer_occupancy(layer + 1, n[2], n[0], n[1], stride, res, gz.iv, gz.cnt, gz.nv)
        xe1, ye1, p1 = layer_vertices(layer + 1, nxt, stride, res, lo, xg, yg, count)
        ze, pz = z_vertices(layer, occ, nxt, stride, res, lo, zg, count + len(p1))
        points += [p1, pz]
        count += len(p1) + len(pz)
        triangles.append(slab_triangles(occ, nxt, xe, ye, xe1, ye1, ze))
        occ, xe, ye = nxt, xe1, ye1
    return np.concatenate(points), np.concatenate(triangles)
