"""One dexel grid: rays along axis k, each holding sorted, disjoint intervals of material.

Ray (iu, iv) of the grid along axis ``k`` runs along e_k through ``u = lo[u] + (iu + 1/2)
res``, ``v = lo[v] + (iv + 1/2) res`` with ``(u, v) = ((k + 1) % 3, (k + 2) % 3)``; its
index is ``iu * nv + iv``. Intervals are stored as float32 offsets from ``lo[k]`` (mm):
``iv[ray, i] = (start, end)`` for ``i < cnt[ray]``, at most ``K`` of them. Rays are cut
tile by tile (``tile`` x ``tile`` rays, :data:`TILES`) on every numba thread; a tile applies
the moves that reach it in program order, so a rapid meets the stock exactly as the earlier
moves left it.
A tile whose ray would need more than K intervals stops at that move: the caller grows K
and the tile resumes there (cutting is idempotent: the move's rays already cut lose nothing
more). A ray that a move cannot cut (:mod:`.sweep_bounds`) is skipped before the closed form
(:mod:`.tool_sweep`), whose per-move terms are computed once a move. numba's cache does not
see edits of those modules (inlined here): clear ``__pycache__/*.nb[ic]`` after one.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .sweep_bounds import misses, misses_box
from .tool_sweep import RAD, band_row, capsule_of, swept_ray

# rays a tile's side, per grid (X, Y, Z): across a +Z program's tool a larger tile meets
# fewer tile-move pairs (the benchmark's Y grid: 0.87 of the CPU at 64 against 32); along it
# the moves' footprints are small and a whole tile is skipped more often at 32 (64: 1.17)
TILES = (64, 64, 32)
SLIVER = 1e-6        # mm: a piece of material shorter than this along a ray is dropped
COLLISION_OVERLAP = 1e-3   # mm: a rapid's tool overlapping material longer than this on a ray
MAX_COLLISIONS = 64  # collisions recorded per tile (distinct moves, first point of each)


@njit(cache=True)
def subtract(iv, r, n, a, b, kmax):
    """Remove [a, b] from the ``n`` sorted intervals of ray ``r`` of ``iv`` (rays, K, 2) in
    place: (new n, or -1 when more than ``kmax`` would be needed; overlap length; t of the
    first overlap)."""
    # i0: the first interval ending after a (binary search; the first one when the cut
    # takes the front of the material, the common case)
    lo_, hi_ = (0, 0) if n == 0 or iv[r, 0, 1] > a else (1, n)
    while lo_ < hi_:
        mid = (lo_ + hi_) >> 1
        if iv[r, mid, 1] <= a:
            lo_ = mid + 1
        else:
            hi_ = mid
    i0 = lo_
    # i1 + 1: the first interval starting at or after b (n when the last one starts before)
    lo_, hi_ = (n, n) if i0 < n and iv[r, n - 1, 0] < b else (i0, n)
    while lo_ < hi_:
        mid = (lo_ + hi_) >> 1
        if iv[r, mid, 0] < b:
            lo_ = mid + 1
        else:
            hi_ = mid
    i1 = lo_ - 1
    if i0 > i1:
        return n, 0.0, 0.0
    overlap = 0.0
    for i in range(i0, i1 + 1):
        overlap += min(float(iv[r, i, 1]), b) - max(float(iv[r, i, 0]), a)
    first = max(float(iv[r, i0, 0]), a)
    s0, e1 = float(iv[r, i0, 0]), float(iv[r, i1, 1])
    left = s0 < a - SLIVER
    right = e1 > b + SLIVER
    p = int(left) + int(right)
    m = i1 - i0 + 1
    new_n = n - m + p
    if new_n > kmax:
        return -1, overlap, first
    shift = p - m
    if shift < 0:
        for i in range(i1 + 1, n):
            iv[r, i + shift, 0] = iv[r, i, 0]
            iv[r, i + shift, 1] = iv[r, i, 1]
    elif shift > 0:
        for i in range(n - 1, i1, -1):
            iv[r, i + shift, 0] = iv[r, i, 0]
            iv[r, i + shift, 1] = iv[r, i, 1]
    j = i0
    if left:
        iv[r, j, 0] = s0
        iv[r, j, 1] = a
        j += 1
    if right:
        iv[r, j, 0] = b
        iv[r, j, 1] = e1
    return new_n, overlap, first


@njit(cache=True)
def _ahead(kept, o, k, tk, p0, p1):
    """Whether the ``kept`` point (3,) comes before the point o with o[k] = tk along the
    move p0 -> p1."""
    s_kept, s_new = 0.0, 0.0
    for i in range(3):
        d = p1[i] - p0[i]
        s_kept += kept[i] * d
        s_new += (tk if i == k else o[i]) * d
    return s_kept <= s_new


@njit(cache=True)
def bin_moves(k, lo, res, nu, nv, bb_lo, bb_hi, tile):
    """Moves per tile (CSR: ``start`` (tiles + 1,), ``moves`` in program order) from the
    moves' boxes ``bb_lo``, ``bb_hi`` (N, 3); ``tile`` rays a tile's side."""
    u, v = (k + 1) % 3, (k + 2) % 3
    ntu, ntv = (nu + tile - 1) // tile, (nv + tile - 1) // tile
    counts = np.zeros(ntu * ntv + 1, np.int64)
    n = bb_lo.shape[0]
    rng = np.empty((n, 4), np.int64)
    for m in range(n):
        a0 = max(0, int(math.floor((bb_lo[m, u] - lo[u]) / res - 0.5)))
        a1 = min(nu - 1, int(math.ceil((bb_hi[m, u] - lo[u]) / res - 0.5)))
        b0 = max(0, int(math.floor((bb_lo[m, v] - lo[v]) / res - 0.5)))
        b1 = min(nv - 1, int(math.ceil((bb_hi[m, v] - lo[v]) / res - 0.5)))
        rng[m, 0], rng[m, 1], rng[m, 2], rng[m, 3] = a0, a1, b0, b1
        if a0 > a1 or b0 > b1:
            continue
        for tu in range(a0 // tile, a1 // tile + 1):
            for tv in range(b0 // tile, b1 // tile + 1):
                counts[tu * ntv + tv + 1] += 1
    start = np.cumsum(counts)
    fill = start[:-1].copy()
    moves = np.empty(start[-1], np.int64)
    for m in range(n):
        a0, a1, b0, b1 = rng[m, 0], rng[m, 1], rng[m, 2], rng[m, 3]
        if a0 > a1 or b0 > b1:
            continue
        for tu in range(a0 // tile, a1 // tile + 1):
            for tv in range(b0 // tile, b1 // tile + 1):
                t = tu * ntv + tv
                moves[fill[t]] = m
                fill[t] += 1
    return start, moves, rng


@njit(cache=True, parallel=True)
def cut_tiles(k, lo, res, nu, nv, tiles, start, moves, rng, p0, p1, table, bounds, rapid,
              bb_lo, bb_hi, init_iv, init_cnt, iv, cnt, ext, resume, col_move, col_at, col_n,
              tile):
    """Cut the grid's ``tiles`` (indices) by their moves: each ray starts from ``init_iv``,
    ``init_cnt`` and loses every move's swept tool (:func:`~.tool_sweep.swept_ray` of the
    move's row of ``table``, :func:`~.tool_sweep.move_table`, unless the row of ``bounds``
    says it cannot cut: :func:`~.sweep_bounds.bounds_table`); p0, p1 (N, 3), rapid (N,)
    bool. Writes ``iv``, ``cnt`` and ``ext`` (rays, 2): each ray's first start and last
    end, read first (one cache line for a ray missed); rapids through material into
    ``col_*`` (per tile: moves (T, C), points (T, C, 3), counts (T,)). ``resume[t]``: where
    tile t starts in ``moves`` (``start[t]``: from the initial stock); set to the move that
    needed more intervals than K, -1 when the tile is done: the caller grows K and calls
    again, the move applied again to the rays it already cut (cutting is idempotent).
    ``tile``: rays a tile's side, as :func:`bin_moves` had them."""
    u, v = (k + 1) % 3, (k + 2) % 3
    ntv = (nv + tile - 1) // tile
    kmax = iv.shape[1]
    for ti in prange(tiles.shape[0]):
        t = tiles[ti]
        tu, tv = t // ntv, t % ntv
        u0, u1 = tu * tile, min(nu, tu * tile + tile) - 1
        v0, v1 = tv * tile, min(nv, tv * tile + tile) - 1
        first_move = resume[t]
        resume[t] = -1
        if first_move == start[t]:
            _load_tile(u0, u1, v0, v1, nv, init_iv, init_cnt, iv, cnt, ext)
            col_n[t] = 0
        o = np.empty(3)
        # the tile's rays' material lies within [te0, te1]: it only shrinks, so an old
        # extent stays a bound; renewed by every move that visits all the tile's rays
        te0, te1 = _tile_extent(u0, u1, v0, v1, nv, cnt, ext)
        cu, hu = lo[u] + (0.5 * (u0 + u1) + 0.5) * res, 0.5 * (u1 - u0) * res
        cv, hv = lo[v] + (0.5 * (v0 + v1) + 0.5) * res, 0.5 * (v1 - v0) * res
        for q in range(first_move, start[t + 1]):
            m = moves[q]
            c, bm = table[m], bounds[m]
            if misses_box(bm, cu, cv, hu, hv, te0, te1):
                continue                # no ray of the tile: the move is behind them all
            tlo, thi = bb_lo[m, k] - lo[k], bb_hi[m, k] - lo[k]
            whole = rng[m, 0] <= u0 and rng[m, 1] >= u1 and rng[m, 2] <= v0 and rng[m, 3] >= v1
            ne0, ne1 = np.inf, -np.inf
            for a in range(max(u0, rng[m, 0]), min(u1, rng[m, 1]) + 1):
                o[u] = lo[u] + (a + 0.5) * res
                o[v], o[k] = lo[v], lo[k]
                row, s = band_row(o[0], o[1], o[2], k, v, c)
                for b in range(max(v0, rng[m, 2]), min(v1, rng[m, 3]) + 1):
                    r = a * nv + b
                    n = cnt[r]
                    if n == 0:
                        continue
                    e0, e1 = ext[r, 0], ext[r, 1]
                    ne0, ne1 = min(ne0, e0), max(ne1, e1)
                    if e1 <= tlo or e0 >= thi:
                        continue
                    o[v] = lo[v] + (b + 0.5) * res
                    if misses(bm, o[u], o[v], e0, e1):
                        continue
                    if row:     # the same as swept_ray, its band segment once a row
                        ta, tb = capsule_of(o[0], o[1], o[2], k, s[0], s[1], s[2], s[3], s[4],
                                            s[5], s[6], s[7], s[8], s[9], s[10], c[RAD])
                    else:
                        ta, tb = swept_ray(o[0], o[1], o[2], k, c, e0, e1)
                    if ta >= tb or tb <= e0 or ta >= e1:
                        continue       # (no material met: subtract would change nothing)
                    n2, overlap, first = subtract(iv, r, n, ta, tb, kmax)
                    if n2 < 0:
                        resume[t] = q
                        break
                    cnt[r] = n2
                    _extent(iv, r, n2, ext)
                    if rapid[m] and overlap > COLLISION_OVERLAP:
                        _collision(t, m, o, u, v, k, lo[k] + first, p0[m], p1[m], col_move,
                                   col_at, col_n)
                if resume[t] >= 0:
                    break
            if resume[t] >= 0:
                break
            if whole:
                te0, te1 = ne0, ne1


@njit(cache=True)
def _tile_extent(u0, u1, v0, v1, nv, cnt, ext):
    """(lowest start, highest end) of the material of the tile's rays (inf, -inf: none)."""
    e0, e1 = np.inf, -np.inf
    for a in range(u0, u1 + 1):
        for b in range(v0, v1 + 1):
            r = a * nv + b
            if cnt[r] > 0:
                e0, e1 = min(e0, ext[r, 0]), max(e1, ext[r, 1])
    return e0, e1


@njit(cache=True)
def _load_tile(u0, u1, v0, v1, nv, init_iv, init_cnt, iv, cnt, ext):
    """The tile's rays (u0..u1, v0..v1) set to their initial stock."""
    for a in range(u0, u1 + 1):
        for b in range(v0, v1 + 1):
            r = a * nv + b
            c = init_cnt[r]
            for i in range(c):
                iv[r, i, 0] = init_iv[r, i, 0]
                iv[r, i, 1] = init_iv[r, i, 1]
            cnt[r] = c
            _extent(iv, r, c, ext)


@njit(cache=True)
def _extent(iv, r, n, ext):
    """``ext[r]`` set to ray r's first start and last end of its ``n`` intervals (1, -1: none)."""
    if n > 0:
        ext[r, 0] = iv[r, 0, 0]
        ext[r, 1] = iv[r, n - 1, 1]
    else:
        ext[r, 0], ext[r, 1] = 1.0, -1.0


@njit(cache=True)
def _collision(t, m, o, u, v, k, tk, p0, p1, col_move, col_at, col_n):
    """Record rapid ``m`` through material at o (o[k] = tk) for tile t: the first point
    met of each move, at most MAX_COLLISIONS moves a tile."""
    c = col_n[t]
    if c > 0 and col_move[t, c - 1] == m:
        c -= 1      # the same move: keep the point met first
        if _ahead(col_at[t, c], o, k, tk, p0, p1):
            return
    elif c == MAX_COLLISIONS:
        return
    col_move[t, c] = m
    col_at[t, c, u] = o[u]
    col_at[t, c, v] = o[v]
    col_at[t, c, k] = tk
    col_n[t] = c + 1


@njit(cache=True, parallel=True)
def grown(iv, kmax):
    """``iv`` (rays, K, 2) copied into (rays, kmax, 2), the new slots zero; on every thread
    (1 GB at the benchmark's K = 64: numpy's copy was 5 s of one core)."""
    out = np.empty((iv.shape[0], kmax, 2), iv.dtype)
    k = iv.shape[1]
    for r in prange(iv.shape[0]):
        for i in range(kmax):
            out[r, i, 0] = iv[r, i, 0] if i < k else 0.0
            out[r, i, 1] = iv[r, i, 1] if i < k else 0.0
    return out
