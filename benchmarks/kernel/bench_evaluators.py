"""Compiled surface evaluators (cadcnc.interp.kernel.evaluators.d2) against OCCT's D2.

For every face of every STEP part given (files, or folders of *.step / *.stp): whether the
kernel supports it (``surface_data`` is not None), the largest deviation from
``BRepAdaptor_Surface::D2`` over ``--points`` (u, w) samples (the parameter box's corners
and random points), as max |d2 - OCCT| / (size + |OCCT|) over the six vectors, size the
part's bounding-box diagonal (mm; the test suite requires <= 1e-12), and the time per
evaluation: d2 in a compiled loop, d2 called from Python, and OCCT from Python
(``FaceSurface.derivative_tuples``: D2 and its six .Coord() calls), all in this process.
Faces above 1e-12 are listed; for B-spline and Bezier faces the listing also gives how
far each evaluation is from the exact one (rational arithmetic on the same knot span), in
the same relative measure: which of the two loses the digits.

    .venv/bin/python -m benchmarks.kernel.bench_evaluators PARTS... [--points N] [--repeat N]
        [--faces]   (one line per face as well)
"""

from __future__ import annotations

import argparse
import math
import time
from collections import defaultdict
from fractions import Fraction
from math import comb
from pathlib import Path

import numba
import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedMapOfShape

from cadcnc.geometry.face_surface import SURFACE_KINDS, FaceSurface
from cadcnc.geometry.step_file import read_step
from cadcnc.geometry.surface_data import SurfaceData, surface_data
from cadcnc.interp.kernel import evaluators as ev
from cadcnc.interp.kernel.bspline import find_span, normalize_periodic

KINDS = list(SURFACE_KINDS.values()) + ["other"]


@numba.njit  # not cached: numba would keep a stale copy of d2 after kernel edits
def compiled_loop(kind, params, ints, knots_u, knots_v, poles, weights, uw, repeat, work,
                  out):
    """d2 at every point of uw ((n, 2)), ``repeat`` times; the sum of statuses."""
    bad = 0
    for _ in range(repeat):
        for k in range(uw.shape[0]):
            bad += ev.d2(kind, params, ints, knots_u, knots_v, poles, weights, uw[k, 0],
                         uw[k, 1], work, out)
    return bad


def part_faces(path: Path) -> tuple[list[FaceSurface], float]:
    """The part's faces (surface models too) and its bounding-box diagonal, mm."""
    shape, _ = read_step(str(path))
    fmap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, fmap)
    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box)
    lo, hi = box.Get()[:3], box.Get()[3:]
    faces = [FaceSurface(TopoDS.Face_s(fmap.FindKey(i)), i)
             for i in range(1, fmap.Extent() + 1)]
    return faces, math.dist(lo, hi)


def samples(face: FaceSurface, n: int, rng) -> np.ndarray:
    """(n, 2): the box's corners, then uniform random points in the face's (u, w) box."""
    (u0, u1), (w0, w1) = face.u_range, face.w_range
    corners = [(u0, w0), (u0, w1), (u1, w0), (u1, w1)]
    return np.vstack([corners, np.c_[rng.uniform(u0, u1, n - 4), rng.uniform(w0, w1, n - 4)]])


def exact_basis(knots: list, k: int, t: Fraction, p: int, nd: int) -> list:
    """[i][j]: d^i N_{k-p+j} / dt^i at t, exactly (The NURBS Book A2.3)."""
    ndu = [[Fraction(0)] * (p + 1) for _ in range(p + 1)]
    left, right = [Fraction(0)] * (p + 1), [Fraction(0)] * (p + 1)
    ndu[0][0] = Fraction(1)
    for j in range(1, p + 1):
        left[j], right[j] = t - knots[k + 1 - j], knots[k + j] - t
        saved = Fraction(0)
        for r in range(j):
            ndu[j][r] = right[r + 1] + left[j - r]
            temp = ndu[r][j - 1] / ndu[j][r]
            ndu[r][j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j][j] = saved
    ders = [[ndu[j][p] for j in range(p + 1)]] + [[Fraction(0)] * (p + 1) for _ in range(nd)]
    for r in range(p + 1):
        a = [[Fraction(1)] + [Fraction(0)] * p, [Fraction(0)] * (p + 1)]
        s1, s2 = 0, 1
        for i in range(1, min(nd, p) + 1):
            d, rk, pk = Fraction(0), r - i, p - i
            if r >= i:
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk]
                d = a[s2][0] * ndu[rk][pk]
            for j in range(1 if rk >= -1 else -rk, (i - 1 if r - 1 <= pk else p - r) + 1):
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j]
                d += a[s2][j] * ndu[rk + j][pk]
            if r <= pk:
                a[s2][i] = -a[s1][i - 1] / ndu[pk + 1][r]
                d += a[s2][i] * ndu[r][pk]
            ders[i][r] = d * math.perm(p, i)
            s1, s2 = s2, s1
    return ders


def exact_d2(data: SurfaceData, u: float, w: float) -> np.ndarray:
    """(6, 3) r .. r_ww of a B-spline / Bezier surface, exactly (rounded at the end)."""
    p, q, per_u, per_w = (int(x) for x in data.ints[1:5])
    umin, umax, wmin, wmax = data.params[12:ev.HEADER]
    side_u = 1 if u == umin else (-1 if u == umax else 0)  # as OCCT at the box edges
    side_w = 1 if w == wmin else (-1 if w == wmax else 0)
    body = data.params[ev.HEADER:]
    u = normalize_periodic(u, body[0], body[1]) if per_u else u
    w = normalize_periodic(w, body[2], body[3]) if per_w else w
    ku, kw = find_span(data.knots_u, p, u, side_u), find_span(data.knots_v, q, w, side_w)
    nu = exact_basis([Fraction(x) for x in data.knots_u], ku, Fraction(u), p, 2)
    nw = exact_basis([Fraction(x) for x in data.knots_v], kw, Fraction(w), q, 2)
    n_u, n_w = data.poles.shape[:2]
    sums = {}
    for a, b in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
        acc = [Fraction(0)] * 4
        for i in range(p + 1):
            for j in range(q + 1):
                iu, iw = (ku - p + i) % n_u, (kw - q + j) % n_w
                c = nu[a][i] * nw[b][j] * Fraction(data.weights[iu, iw])
                acc = [x + c * Fraction(y) for x, y in zip(acc, [*data.poles[iu, iw], 1.0])]
        sums[a, b] = acc
    res = {}
    for a, b in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
        val = sums[a, b][:3]
        for i in range(a + 1):
            for j in range(b + 1):
                if i or j:
                    c = comb(a, i) * comb(b, j) * sums[i, j][3]
                    val = [x - c * y for x, y in zip(val, res[a - i, b - j])]
        res[a, b] = [x / sums[0, 0][3] for x in val]
    res[0, 0] = [x + Fraction(o) for x, o in zip(res[0, 0], body[4:7])]  # poles from O
    order = ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2))
    return np.array([[float(x) for x in res[k]] for k in order])


def versus_exact(face: FaceSurface, data: SurfaceData, size: float, uw: np.ndarray) -> tuple:
    """(kernel, OCCT) max deviation from the exact d2 over the samples."""
    work, out, ref = ev.new_work(), np.zeros((6, 3)), np.zeros((6, 3))
    worst = [0.0, 0.0]
    for u, w in uw:
        exact = exact_d2(data, u, w)
        scale = size + np.linalg.norm(exact, axis=1)
        ev.d2(*data.args, u, w, work, out)
        face.derivatives_array(u, w, ref)
        for n, got in enumerate((out, ref)):
            worst[n] = max(worst[n], float((np.linalg.norm(got - exact, axis=1) / scale).max()))
    return tuple(worst)


def timed_per_call(fn, uw: np.ndarray, repeat: int) -> float:
    """Mean seconds per fn(u, w) over the points, ``repeat`` passes."""
    pts = [(float(u), float(w)) for u, w in uw]
    t0 = time.perf_counter()
    for _ in range(repeat):
        for u, w in pts:
            fn(u, w)
    return (time.perf_counter() - t0) / (repeat * len(pts))


def measure(face: FaceSurface, size: float, n: int, repeat: int, rng) -> dict:
    """One face's figures: deviation (relative, see the module docstring), times in s."""
    row = {"face": face.number, "kind": face.kind, "supported": False, "dev": math.nan,
           "fallback": 0, "t_loop": math.nan, "t_py": math.nan, "exact": None}
    uw = samples(face, n, rng)
    row["t_occt"] = timed_per_call(face.derivative_tuples, uw, repeat)
    data = surface_data(face)
    if data is None:
        return row
    row["supported"] = True
    work, out, ref = ev.new_work(), np.zeros((6, 3)), np.zeros((6, 3))
    dev = 0.0
    for u, w in uw:
        if ev.d2(*data.args, u, w, work, out) != ev.OK:
            row["fallback"] += 1
            continue
        face.derivatives_array(u, w, ref)
        err = np.linalg.norm(out - ref, axis=1) / (size + np.linalg.norm(ref, axis=1))
        dev = max(dev, float(err.max()))
    row["dev"] = dev
    if dev > 1e-12 and face.kind in ("bspline", "bezier"):
        row["exact"] = versus_exact(face, data, size, uw)
    args = data.args
    row["t_py"] = timed_per_call(lambda u, w: ev.d2(*args, u, w, work, out), uw, repeat)
    loops = max(1, 20 * repeat)
    t0 = time.perf_counter()
    compiled_loop(*args, uw, loops, work, out)
    row["t_loop"] = (time.perf_counter() - t0) / (loops * len(uw))
    return row


def table(title: str, rows: list[dict]) -> list[str]:
    """Per-kind lines: faces, supported, max deviation, times (ns compiled, us Python)."""
    lines = [f"{title}", f"  {'kind':11s} {'faces':>5s} {'suppd':>5s} {'max dev':>9s} "
             f"{'loop ns':>8s} {'py->d2 us':>9s} {'OCCT us':>8s} {'OCCT/loop':>9s}"]
    by_kind = defaultdict(list)
    for r in rows:
        by_kind[r["kind"]].append(r)
    for kind in KINDS:
        group = by_kind.get(kind)
        if not group:
            continue
        sup = [r for r in group if r["supported"]]
        dev = max((r["dev"] for r in sup), default=math.nan)
        occt = np.mean([r["t_occt"] for r in group]) * 1e6
        loop = np.mean([r["t_loop"] for r in sup]) * 1e9 if sup else math.nan
        py = np.mean([r["t_py"] for r in sup]) * 1e6 if sup else math.nan
        lines.append(f"  {kind:11s} {len(group):5d} {len(sup):5d} {dev:9.1e} {loop:8.0f} "
                     f"{py:9.2f} {occt:8.2f} {occt * 1e3 / loop:9.0f}")
    return lines


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("parts", nargs="+", help="STEP files or folders of them")
    ap.add_argument("--points", type=int, default=50, help="(u, w) samples per face")
    ap.add_argument("--repeat", type=int, default=20, help="timing passes over the samples")
    ap.add_argument("--faces", action="store_true", help="print one line per face too")
    args = ap.parse_args(argv)
    files = []
    for p in map(Path, args.parts):
        files += sorted(q for q in p.iterdir() if q.suffix.lower() in (".step", ".stp")) \
            if p.is_dir() else [p]
    t0 = time.perf_counter()
    for warm in part_faces(files[0])[0]:  # compile d2 and the loop outside the clocks
        data = surface_data(warm)
        if data is not None:
            compiled_loop(*data.args, samples(warm, 4, np.random.default_rng(0)), 1,
                          ev.new_work(), np.zeros((6, 3)))
            break
    print(f"compile / cache load: {time.perf_counter() - t0:.1f} s")
    rng = np.random.default_rng(1)
    everything, outliers = [], []
    for path in files:
        faces, size = part_faces(path)
        rows = [measure(f, size, args.points, args.repeat, rng) for f in faces]
        everything += rows
        print("\n".join(table(f"{path.name}: {len(faces)} faces, size {size:.1f} mm", rows)))
        if args.faces:
            for r in rows:
                print(f"    face {r['face']:4d} {r['kind']:11s} "
                      f"{'supported' if r['supported'] else 'OCCT only':9s} "
                      f"dev {r['dev']:8.1e}  loop {r['t_loop'] * 1e9:6.0f} ns  "
                      f"py->d2 {r['t_py'] * 1e6:5.2f} us  OCCT {r['t_occt'] * 1e6:5.2f} us")
        outliers += [(path.name, r) for r in rows if r["dev"] > 1e-12 or r["fallback"]]
        unsupported = sorted({r["kind"] for r in rows if not r["supported"]})
        if unsupported:
            print(f"  unsupported kinds here: {', '.join(unsupported)}")
    print("\n".join(table("all parts", everything)))
    if outliers:
        print("faces above 1e-12 or with fallbacks (B-spline: each one's deviation from the "
              "exact values):")
        for name, r in outliers:
            exact = "" if r["exact"] is None else \
                f", from exact: kernel {r['exact'][0]:.1e}, OCCT {r['exact'][1]:.1e}"
            print(f"  {name} face {r['face']} {r['kind']}: dev {r['dev']:.1e}{exact}, "
                  f"fallbacks {r['fallback']}")


if __name__ == "__main__":
    main()
