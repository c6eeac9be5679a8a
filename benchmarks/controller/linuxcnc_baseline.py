"""LinuxCNC's own planner on test programs, headless, measured per servo period (issue 22).

For each test curve (a circle R 10 mm in XY; a 3-D Lissajous curve with varying curvature),
each feed and each ``G64 P``, writes the curve as a G1 polyline (points on the exact curve,
Douglas-Peucker to 1 µm with cadcnc's own ``simplify``), runs it through LinuxCNC 2.9
(``linuxcnc`` with ``linuxcncrsh``, trivkins, the machine's axis limits and servo period),
samples the joint commands every period and measures:

- cycle time: from the period the first G1 starts to the last period the position changes;
- contour error: distance of every sampled position to the exact curve (max, p99);
- violations: samples over the axes' velocity, acceleration, jerk (backward finite
  differences; slack 1e-6 relative plus the 1e-9 mm sampling quantum).

The column "constant feed, limit3" streams the exact curve at the programmed feed from the
first period (no planning) through HAL with ``limit3`` at the machine's limits, and is
measured the same way. Writes ``results_<polyline>.json`` and each run's sampled positions (.npy) to
``--out``.

    .venv/bin/python benchmarks/controller/linuxcnc_baseline.py [--out DIR] [--quick]
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from cadcnc.controller.hal import run_hal_loop
from cadcnc.controller.hal.linuxcnc_sim import run_ngc
from cadcnc.io.gcode import simplify

QUANTUM = 1e-9  # mm: resolution of the sampled positions (µm printed with 6 decimals)


@dataclass(frozen=True)
class Limits:
    """A faster machine than the default (s, mm/s, mm/s², mm/s³): the synthetic table's."""

    period: float = 0.001
    max_velocity: tuple = (10000 / 60, 10000 / 60, 5000 / 60)
    max_acceleration: tuple = (1000.0, 1000.0, 500.0)
    max_jerk: tuple = (1e5, 1e5, 5e4)


def circle(u: np.ndarray) -> np.ndarray:
    """A circle of radius 10 mm in XY centred at the origin, Z 0; u in [0, 1]."""
    t = 2 * np.pi * u
    return np.stack([10 * np.cos(t), 10 * np.sin(t), 0 * t], axis=1)


def lissajous(u: np.ndarray) -> np.ndarray:
    """A closed 3-D curve with curvature from ~0.02 to ~0.4 1/mm; u in [0, 1]."""
    t = 2 * np.pi * u
    return np.stack([30 * np.sin(t), 12 * np.sin(2 * t), 2 * np.sin(3 * t)], axis=1)


CURVES = {"circle": circle, "lissajous": lissajous}


class Exact:
    """A curve densely sampled (0.002 mm): arc length, distance of points to the curve."""

    def __init__(self, curve, h: float = 0.002):
        rough = curve(np.linspace(0, 1, 20001))
        length = np.linalg.norm(np.diff(rough, axis=0), axis=1).sum()
        self.pts = curve(np.linspace(0, 1, int(length / h) + 1))
        seg = np.linalg.norm(np.diff(self.pts, axis=0), axis=1)
        self.s = np.concatenate([[0], np.cumsum(seg)])
        self.length = float(self.s[-1])
        self.tree = cKDTree(self.pts)

    def at_length(self, s: np.ndarray) -> np.ndarray:
        """Points at arc lengths ``s`` (mm), linear between dense samples."""
        return np.stack([np.interp(s, self.s, self.pts[:, k]) for k in range(3)], axis=1)

    def distance(self, p: np.ndarray) -> np.ndarray:
        """Distance of each point to the curve (nearest of the two dense segments), mm."""
        _, k = self.tree.query(p)
        best = np.full(len(p), np.inf)
        for a_i, b_i in ((k - 1, k), (k, k + 1)):
            a_i, b_i = np.clip(a_i, 0, len(self.pts) - 1), np.clip(b_i, 0, len(self.pts) - 1)
            a, b = self.pts[a_i], self.pts[b_i]
            ab = b - a
            den = np.maximum((ab * ab).sum(1), 1e-300)
            t = np.clip(((p - a) * ab).sum(1) / den, 0, 1)
            best = np.minimum(best, np.linalg.norm(p - (a + t[:, None] * ab), axis=1))
        return best


def polyline(exact: Exact, mode: str, feed: float, period: float) -> np.ndarray:
    """The G1 points: ``dp``, points every 0.01 mm simplified to 1 µm (cadcnc's simplify);
    ``step``, one point per period at the feed (cadcnc's G-code with no tolerance)."""
    if mode == "step":
        return exact.at_length(np.append(np.arange(0, exact.length, feed / 60 * period),
                                         exact.length))
    pts = exact.at_length(np.linspace(0, exact.length, int(exact.length / 0.01) + 1))
    return pts[simplify(pts, 1e-3)]


def write_ngc(points: np.ndarray, feed: float, p: float, path: Path) -> int:
    """A G-code program: rapid to the first point, G1 through the rest; the first G1 line."""
    head = ["G21 G17 G90 G94", f"G64 P{p:.7f}",
            "G0 X{:.6f} Y{:.6f} Z{:.6f}".format(*points[0]), f"F{feed:.3f}"]
    body = ["G1 X{:.6f} Y{:.6f} Z{:.6f}".format(*q) for q in points[1:]]
    path.write_text("\n".join(head + body + ["M2", ""]))
    return len(head) + 1  # 1-based line of the first G1



def violations(w: np.ndarray, m) -> dict:
    """Per limit (v, a, j) of ``m``, the samples of positions ``w`` (K, 3) over it by
    finite differences at the servo period (1e-6 relative slack, plus the samples'
    resolution), and the peak share of the limit."""
    dt = m.period
    v = np.diff(w, axis=0) / dt
    a = np.diff(v, axis=0) / dt
    j = np.diff(a, axis=0) / dt
    out = {}
    for name, d, lim, q in (("v", v, m.max_velocity, 2 * QUANTUM / dt),
                            ("a", a, m.max_acceleration, 4 * QUANTUM / dt ** 2),
                            ("j", j, m.max_jerk, 8 * QUANTUM / dt ** 3)):
        lim = np.asarray(lim, dtype=float)
        over = np.abs(d) > lim * (1 + 1e-6) + q
        out[f"{name}_over"] = int(over.any(axis=1).sum())
        out[f"{name}_peak_share"] = float((np.abs(d) / lim).max())
    return out

def measure(pos: np.ndarray, start: int, exact: Exact, m, end_point) -> dict:
    """Cycle time, contour error and limit violations of sampled positions (mm, s)."""
    moving = np.nonzero(np.abs(np.diff(pos, axis=0)).max(1) > QUANTUM)[0]
    end = int(moving[-1]) + 1 if len(moving) else start
    cut = pos[start:end + 1]
    err = exact.distance(cut)
    w = pos[max(start - 3, 0):end + 4]
    dt = m.period
    out = {"cycle_time_s": (end - start) * dt, "periods": end - start,
           "contour_max_mm": float(err.max()), "contour_p99_mm": float(np.percentile(err, 99)),
           "end_error_mm": float(np.linalg.norm(pos[end] - end_point))}
    out.update(violations(w, m))
    return out


def constant_feed(exact: Exact, feed: float, m) -> np.ndarray:
    """The exact curve at ``feed`` mm/min from the first period to the last (no ramps)."""
    step = feed / 60 * m.period
    s = np.append(np.arange(0, exact.length, step), exact.length)
    return exact.at_length(s)


def run_case(name: str, feed: float, ps: list[float], m, out: Path,
             mode: str = "dp", constant: bool = True) -> list[dict]:
    """Every P for one curve and feed, then the constant-feed stream; a row each."""
    exact = Exact(CURVES[name])
    pts = polyline(exact, mode, feed, m.period)
    rows = []
    for p in ps:
        ngc = out / f"{name}_F{feed:g}_P{p:g}_{mode}.ngc"
        first_g1 = write_ngc(pts, feed, p, ngc)
        t0 = time.monotonic()
        r = run_ngc(ngc, m)
        start = int(np.argmax(r.line >= first_g1))
        np.save(ngc.with_suffix(".npy"), r.positions)
        row = {"curve": name, "feed": feed, "method": f"LinuxCNC G64 P{p:g}",
               "polyline": mode, "segments": len(pts) - 1, "error": r.error,
               "wall_s": round(time.monotonic() - t0, 2),
               **measure(r.positions, start, exact, m, pts[-1])}
        rows.append(row)
        print(_line(row), flush=True)
    if not constant:
        return rows
    stream = constant_feed(exact, feed, m)
    t0 = time.monotonic()
    h = run_hal_loop(stream, m, limits="machine", tail=int(3 / m.period))
    np.save(out / f"{name}_F{feed:g}_constant_limit3.npy", h.executed)
    row = {"curve": name, "feed": feed, "method": "constant feed, limit3",
           "polyline": "stream", "segments": len(stream) - 1, "error": f"clipped {h.clipped}, underruns "
           f"{h.underruns}", "wall_s": round(time.monotonic() - t0, 2),
           **measure(h.executed, 0, exact, m, stream[-1])}
    rows.append(row)
    print(_line(row), flush=True)
    return rows


def _line(r: dict) -> str:
    return (f"{r['curve']:9s} F{r['feed']:<6g} {r['method']:22s} T {r['cycle_time_s']:7.3f} s "
            f"[{r['polyline']:6s} {r['segments']:5d}] err max {r['contour_max_mm']:.2e} p99 {r['contour_p99_mm']:.2e} mm  "
            f"over v/a/j {r['v_over']}/{r['a_over']}/{r['j_over']} "
            f"(peak {r['v_peak_share']:.2f}/{r['a_peak_share']:.2f}/{r['j_peak_share']:.1f})"
            f"  [{r['error']}]")


def machine_under_test(args):
    """``--machine fast`` (default): :class:`Limits`, the machine of the synthetic-curve
    table in docs/notes/controller.md; ``default``: cadcnc's ``Machine.default()``."""
    if args.machine == "default":
        from cadcnc.controller.machine import Machine
        return Machine.default()
    return Limits()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=Path("/tmp/cadcnc-linuxcnc-baseline"))
    ap.add_argument("--quick", action="store_true", help="circle only, P 0.001 only")
    ap.add_argument("--feeds", type=float, nargs="+", default=[1500.0, 10000.0])
    ap.add_argument("--polyline", choices=["dp", "step"], default="dp",
                    help="G1 points: simplified to 1 µm (dp) or one per period (step)")
    ap.add_argument("--no-constant", action="store_true", help="skip the limit3 column")
    ap.add_argument("--machine", choices=["fast", "default"], default="fast",
                    help="fast: v 166.7/166.7/83.3 mm/s, a 1000/1000/500 mm/s² (the notes' "
                         "table); default: Machine.default() (the Tormach PCNC 770)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    m = machine_under_test(args)
    print(f"machine: period {m.period} s, v {m.max_velocity} mm/s, a {m.max_acceleration} "
          f"mm/s², j {m.max_jerk} mm/s³ (LinuxCNC 2.9 ignores jerk)")
    ps = [0.001] if args.quick else [0.0001, 0.001, 0.01]
    rows = []
    for name in (["circle"] if args.quick else list(CURVES)):
        for feed in args.feeds:
            rows += run_case(name, feed, ps, m, args.out, args.polyline, not args.no_constant)
    (args.out / f"results_{args.polyline}.json").write_text(json.dumps(
        {"machine": {k: getattr(m, k) for k in ("period", "max_velocity", "max_acceleration",
                                                 "max_jerk")}, "rows": rows}, indent=1))
    print(f"wrote {args.out / f'results_{args.polyline}.json'}")


if __name__ == "__main__":
    main()
