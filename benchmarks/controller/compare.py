"""The direct stream in HAL against LinuxCNC's own planner, on the project's programs (issue 22).

Three programs (stream_cost.programs(): the corner bspline_boss faces 4 5 R 3, the pencil
program of step_block R 3, the finishing program of finish_fillet faces 6 3 R 3 stepover
10), each at its feed (1500 mm/min) and at 10 000 mm/min, on one machine
(``Machine.default()``: the Tormach PCNC 770, 1 ms servo period). Columns:

- ``stream``: ``stream_program`` (feed planned to v, a, j), executed by HAL: streamer into
  one ``limit3`` per axis at the machine's v and a, read back by halsampler;
- ``LinuxCNC P``: the program's own G-code (``program_ngc`` with ``tolerance`` 1e-5 mm:
  the kernel's points, dropped only within 10 nm of a chord, 6 decimals; the F words replaced by the feed; a 1 ms dwell after the writer's rapid to
  the first point, so that the run starts at rest there as the stream does) with
  ``G64 P`` 0.0001, 0.001, 0.01 mm,
  run by LinuxCNC 2.9 headless (``run_ngc``: trapezoidal planner, same per-axis v and a,
  no jerk limit), its joint commands sampled per period;
- ``constant``: the stream at the programmed feed ignoring the limits (positions as
  computed, not executed: what the program asks for);
- ``const+limit3``: that constant-feed stream executed by HAL through ``limit3``.

Measured on the sampled positions, all the same way:

- cycle time: from the last period at the program's first point to the last period the
  position changes;
- contour error: distance of each sample to the exact path, i.e. the program re-run by the
  kernel at 1 µm steps (``stream_program`` at constant feed with a 50 µs period; chord sag
  of that reference under 1e-7 mm), links as their straight moves; max and p99;
- violations: samples over each axis's v, a, j (backward differences of the samples;
  slack 1e-6 relative plus the 1e-9 mm sampling quantum), and the largest share of each.

Runs every case once (several minutes: LinuxCNC starts in ~4 s, HAL runs in real time);
writes ``results.json`` and each run's positions to ``--out``; ``--plot`` only redraws
``docs/img/controller_compare.png`` from ``--out``.

    .venv/bin/python benchmarks/controller/compare.py [--out DIR] [--plot]
"""

from __future__ import annotations

import argparse
import json
import re
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from cadcnc.controller import Machine, stream_program
from cadcnc.controller.hal import HalError, run_hal_loop
from cadcnc.controller.hal.linuxcnc_sim import run_ngc
from cadcnc.io.program_gcode import program_ngc
from cadcnc.ops.stream_steppers import stepper_factory

from benchmarks.controller.linuxcnc_baseline import violations
from benchmarks.controller.stream_cost import programs

QUANTUM = 1e-9          # mm: the samples' resolution (µm printed with 6 decimals)
REF_PERIOD = 5e-5       # s: the reference's period ...
REF_FEED = 1200.0       # mm/min: ... and feed: 1 µm steps
FEEDS = (1500.0, 10_000.0)
PS = (0.0001, 0.001, 0.01)
NGC_TOLERANCE = 1e-5    # mm: cadcnc's writer with --tolerance 0.00001 (6 decimals)
IMG = Path(__file__).resolve().parents[2] / "docs" / "img" / "controller_compare.png"


class Reference:
    """The exact path as a dense polyline (1 µm steps on cuts; links exact lines)."""

    def __init__(self, program, part, machine: Machine):
        fine = replace(machine, period=REF_PERIOD)
        s = stream_program(program, fine, stepper_factory(part), feed=REF_FEED, planned=False)
        self.pts = s.positions
        self.tree = cKDTree(self.pts)
        self.hermite_cuts = s.hermite_cuts

    def distance(self, p: np.ndarray, k: int = 32) -> np.ndarray:
        """Distance of each point to the reference polyline (segments next to the k
        nearest vertices: k large, since a cut's ends meet links at one point), mm."""
        _, idx = self.tree.query(p, k=k)
        best = np.full(len(p), np.inf)
        n = len(self.pts)
        for c in range(k):
            for a_i in (idx[:, c] - 1, idx[:, c]):
                a_i = np.clip(a_i, 0, n - 2)
                a, b = self.pts[a_i], self.pts[a_i + 1]
                ab = b - a
                den = np.maximum((ab * ab).sum(1), 1e-300)
                t = np.clip(((p - a) * ab).sum(1) / den, 0, 1)
                best = np.minimum(best, np.linalg.norm(p - (a + t[:, None] * ab), axis=1))
        return best


def window(pos: np.ndarray, first: np.ndarray, near: float = 2e-4) -> tuple[int, int]:
    """(start, end): the last period at rest at the program's first point, the last
    period the position changes."""
    moving = np.abs(np.diff(pos, axis=0)).max(1) > QUANTUM
    at = np.flatnonzero(np.linalg.norm(pos - first, axis=1) < near)
    if not len(at):
        raise RuntimeError("the run never reached the program's first point")
    start = int(at[0])
    while start < len(moving) and not moving[start]:
        start += 1
    end = int(np.flatnonzero(moving)[-1]) + 1
    return start, end


def measure(pos: np.ndarray, first: np.ndarray, ref: Reference, m: Machine) -> dict:
    """Cycle time, contour error and limit violations of sampled positions (mm, s)."""
    start, end = window(pos, first)
    run = pos[start:end + 1]
    err = ref.distance(run)
    w = pos[max(start - 3, 0):end + 4]
    dt = m.period
    out = {"cycle_time_s": (end - start) * dt, "contour_max_mm": float(err.max()),
           "contour_p99_mm": float(np.percentile(err, 99)),
           "contour_p50_mm": float(np.percentile(err, 50))}
    out.update({k.replace("_peak_share", "_share"): x for k, x in violations(w, m).items()})
    return out


def ngc_text(program, feed: float, p: float) -> str:
    """The program's own G-code with ``G64 P p`` and every F word set to ``feed``."""
    text = program_ngc(program, blend=p, tolerance=NGC_TOLERANCE)
    text = re.sub(r"^F[0-9.]+$", f"F{feed:.3f}", text, flags=re.MULTILINE)
    # the writer's prelude (G0 Z, G0 X Y to the first point) would blend into the first
    # link: a 1 ms dwell makes the run start at rest on the first point, as the stream does
    return re.sub(r"^(G0 X[^\n]*)$", r"\1\nG4 P0.001", text, count=1, flags=re.MULTILINE)


def ngc_floor(program, ref: Reference) -> float:
    """The largest distance of the written G-code polyline (8 points per chord) from the
    exact path: the contour error LinuxCNC would have with P = 0."""
    from cadcnc.io.program_gcode import segment_moves

    worst = 0.0
    for pts in segment_moves(program_ngc(program, tolerance=NGC_TOLERANCE)):
        if len(pts) < 2:
            continue
        t = np.linspace(0, 1, 9)[:, None, None]
        q = (pts[:-1][None] * (1 - t) + pts[1:][None] * t).reshape(-1, 3)
        worst = max(worst, float(ref.distance(q).max()))
    return worst


def run_all(out: Path, only: list[str] | None = None) -> list[dict]:
    machine = Machine.default()
    done = out / "results.json"
    rows = [r for r in json.loads(done.read_text()) if only and not
            r["program"].startswith(tuple(only))] if only and done.exists() else []
    for name, part, program in programs():
        if only and not name.startswith(tuple(only)):
            continue
        t0 = time.monotonic()
        ref = Reference(program, part, machine)
        first = program.segments[0].points[0]
        print(f"{name}: reference {len(ref.pts)} points in {time.monotonic() - t0:.1f} s "
              f"({ref.hermite_cuts} roll-over cuts from their points)", flush=True)
        tag = name.split()[0]
        floor = ngc_floor(program, ref)
        print(f"  the G-code polyline itself: max {floor:.2e} mm from the exact path", flush=True)
        for feed in FEEDS:
            fset = None if feed == program.job.feed else feed
            cases, failed = [], []
            s = stream_program(program, machine, stepper_factory(part), feed=fset)
            h = run_hal_loop(s.positions, machine, limits="machine")
            cases.append(("stream", h.executed, {"clipped": h.clipped, "underruns":
                                                 h.underruns, "planned_s": s.cycle_time}))
            for p in PS:
                ngc = out / f"{tag}_F{feed:g}_P{p:g}.ngc"
                ngc.write_text(ngc_text(program, feed, p))
                try:
                    r = run_ngc(ngc, machine, timeout=120)
                except HalError as e:   # recorded, not hidden: the row says why
                    print(f"  LinuxCNC P{p:g} failed: {e}", flush=True)
                    failed.append({"program": name, "feed": feed, "method": f"LinuxCNC P{p:g}",
                                   "error": str(e).splitlines()[0]})
                    continue
                cases.append((f"LinuxCNC P{p:g}", r.positions, {"error": r.error}))
            c = stream_program(program, machine, stepper_factory(part), feed=fset,
                               planned=False)
            cases.append(("constant", np.vstack([c.positions, c.positions[-1:]]), {}))
            hc = run_hal_loop(c.positions, machine, limits="machine")
            cases.append(("const+limit3", hc.executed, {"clipped": hc.clipped,
                                                        "underruns": hc.underruns}))
            for method, pos, extra in cases:
                np.save(out / f"{tag}_F{feed:g}_{method.replace(' ', '_')}.npy", pos)
                row = {"program": name, "feed": feed, "method": method, "ngc_floor_mm": floor,
                       **measure(pos, first, ref, machine), **extra}
                rows.append(row)
                print(line(row), flush=True)
            rows += failed
        (out / "results.json").write_text(json.dumps(rows, indent=1))
    return rows


def remeasure(out: Path) -> list[dict]:
    """The rows of ``results.json`` measured again from the saved positions (no run)."""
    machine = Machine.default()
    rows = json.loads((out / "results.json").read_text())
    for name, part, program in programs():
        ref = Reference(program, part, machine)
        first = program.segments[0].points[0]
        floor = ngc_floor(program, ref)
        for row in rows:
            if row["program"] != name or "cycle_time_s" not in row:
                continue
            pos = np.load(out / f"{name.split()[0]}_F{row['feed']:g}_"
                                f"{row['method'].replace(' ', '_')}.npy")
            row.update(ngc_floor_mm=floor, **measure(pos, first, ref, machine))
            print(line(row), flush=True)
    (out / "results.json").write_text(json.dumps(rows, indent=1))
    return rows


def line(r: dict) -> str:
    return (f"{r['program'][:8]:8s} F{r['feed']:<6g} {r['method']:16s} T {r['cycle_time_s']:7.3f}"
            f" s  err max {r['contour_max_mm']:.2e} p99 {r['contour_p99_mm']:.2e} mm  over "
            f"v/a/j {r['v_over']}/{r['a_over']}/{r['j_over']} (peak {r['v_share']:.2f}/"
            f"{r['a_share']:.2f}/{r['j_share']:.1f}) "
            + " ".join(f"{k}={v}" for k, v in r.items() if k in
                       ("clipped", "underruns", "error", "planned_s")))


def plot(out: Path) -> None:
    """Executed feed against arc length, the three programs at 10 000 mm/min."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    machine = Machine.default()
    names = {"corner": "corner bspline_boss 4 5", "pencil": "pencil step_block",
             "finish": "finish finish_fillet 6 3"}
    rows = json.loads((out / "results.json").read_text())
    fig, axes = plt.subplots(3, 1, figsize=(11, 9))
    for ax, (tag, title) in zip(axes, names.items()):
        for method, style in (("constant", dict(color="0.6", lw=0.8, ls=":")),
                              ("LinuxCNC P0.01", dict(color="tab:orange", lw=0.7)),
                              ("LinuxCNC P0.0001", dict(color="tab:red", lw=0.7)),
                              ("stream", dict(color="tab:blue", lw=1.0))):
            f = out / f"{tag}_F10000_{method.replace(' ', '_')}.npy"
            if not f.exists():
                continue
            pos = np.load(f)
            first = np.load(out / f"{tag}_F10000_stream.npy")[0]
            start, end = window(pos, first)   # from rest at the first point, as measured
            pos = pos[start:end + 1]
            row = next(r for r in rows if r["program"] == title and r["feed"] == 10000
                       and r["method"] == method)
            step = np.linalg.norm(np.diff(pos, axis=0), axis=1)
            moving = np.flatnonzero(step > QUANTUM)
            step = step[moving[0]:moving[-1] + 1]
            arc = np.cumsum(step)
            ax.plot(arc, 60 * step / machine.period, label=f"{method}: "
                    f"{row['cycle_time_s']:.2f} s, contour max {row['contour_max_mm']:.1e} mm",
                    **style)
        ax.set_title(f"{title}, F 10 000 mm/min", fontsize=9)
        ax.set_ylabel("executed feed, mm/min")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("arc length executed (cuts and links), mm")
    fig.suptitle(f"Executed feed: the planned stream in HAL vs LinuxCNC 2.9's planner; "
                 f"{machine.source}", fontsize=9)
    fig.tight_layout()
    fig.savefig(IMG, dpi=100)
    print(f"wrote {IMG}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=Path("/tmp/cadcnc-compare"))
    ap.add_argument("--plot", action="store_true", help="only redraw the plot from --out")
    ap.add_argument("--only", nargs="+", metavar="PROGRAM",
                    help="run only these programs (corner, pencil, finish), keeping the "
                         "other rows of --out/results.json")
    ap.add_argument("--remeasure", action="store_true",
                    help="measure the positions saved in --out again (no HAL, no LinuxCNC)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.remeasure:
        remeasure(args.out)
    elif not args.plot:
        run_all(args.out, args.only)
    plot(args.out)


if __name__ == "__main__":
    main()
