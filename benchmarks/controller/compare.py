"""The race: the direct stream in HAL against LinuxCNC 2.9's planner, on fair terms (issue 35).

Three programs (stream_cost.programs(): the corner bspline_boss faces 4 5 R 3, the pencil
program of step_block R 3, the finishing program of finish_fillet faces 6 3 R 3 stepover
10) at FEED mm/min on two machines (``MACHINES``): ``Machine.default()`` (the Tormach
PCNC 770) and a high-speed mill (``high_speed_mill``). Per machine and program:

- ``stream``: ``stream_program`` (feed planned to v, a, j), executed by HAL (streamer into
  one ``limit3`` per axis at the machine's v and a, read back by halsampler);
- ``LinuxCNC P``: the program's own G-code (``program_ngc``, tolerance 1e-5 mm, 6 decimals,
  every F word the feed, a 1 ms dwell at the first point so that the run starts at rest
  there as the stream does) at ``G64 P`` for P in PS, run by LinuxCNC 2.9 headless
  (``run_ngc``: trapezoidal planner, same v and a, no jerk limit), sampled per period;
- ``LinuxCNC equal``: G-code dense enough for the stream's accuracy: lines by their ends,
  arcs and corner paths as polylines within half the equal tolerance of the exact path
  (arcs from their fitted circle; corner paths from the kernel re-run at 2.5 µm steps,
  Douglas-Peucker, points off the offset surfaces moved onto them; passes on free-form
  faces the kernel's points at 2.5 µm steps, so their own error stays in), 7 decimals,
  at ``G64 P`` half of it. The equal tolerance is the stream's own measured true contour
  error (its planned rows against their pieces), at least EQUAL_TOL: LinuxCNC gets the
  stream's error, not less. LinuxCNC's timeout grows with the lines (it runs about one
  a period).

Measured on the sampled positions, all the same way:

- cycle time: from the last period at rest at the program's first point to the last
  period the position changes; ``last`` the time on the final move (the retract):
  LinuxCNC 2.9 plans a lone or last segment at half the acceleration (LinuxCNC issue
  #4220, fixed upstream after 2.9), and ``last_full_s`` is that move at full acceleration;
- bound: ``bound.va_bound`` (TOPP-RA, 100 % of v and a, no jerk, stops at corners);
- true contour error: ``contour.PathReference`` (closed-form lines and arcs, the two offset
  surfaces by OCCT for corner paths), each sample against the nearest piece; the stream's
  planned rows also against their own piece (``own_max_mm``); max and p99;
- violations: samples over each axis's v, a, j (backward differences; 1e-6 relative slack
  plus the 1e-9 mm sampling quantum), and the largest share of each.

Writes ``results.json`` and each run's positions to ``--out``.

    .venv/bin/python benchmarks/controller/compare.py [--out DIR] [--machines default hsm]
"""

from __future__ import annotations

import argparse
import json
import math
import re
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from benchmarks.controller.linuxcnc_baseline import violations
from benchmarks.controller.stream_cost import programs
from cadcnc.controller import Machine, stream_program
from cadcnc.controller.hal import HalError, run_hal_loop
from cadcnc.controller.hal.linuxcnc_sim import SAMPLE_DEPTH, run_ngc
from cadcnc.io.gcode import simplify
from cadcnc.io.program_gcode import program_ngc
from cadcnc.ops.stream_steppers import stepper_factory
from cadcnc.testing.contour_reference import Arc, Guided, Offsets, PathReference
from cadcnc.testing.topp_bound import va_bound

QUANTUM = 1e-9          # mm: the samples' resolution
FEED = 10_000.0         # mm/min
PS = (0.0001, 0.01)     # mm: LinuxCNC on the program's own G-code
NGC_TOLERANCE = 1e-5    # mm: cadcnc's writer with --tolerance 0.00001 (6 decimals)
EQUAL_TOL = 1e-6        # mm: the least equal tolerance (the dense G-code: its polyline
                        # within half, and P half)
DENSE_PERIOD, DENSE_FEED = 5e-5, 3000.0   # s, mm/min: the kernel's 2.5 µm steps


def high_speed_mill() -> Machine:
    """A high-speed mill: Hermle C 22 U's published rapid traverse (35 m/min) and linear
    acceleration (5 m/s²) on every axis; jerk ours (50 000 mm/s³: a in 0.1 s); 1 ms."""
    return Machine(0.001, (35_000 / 60,) * 3, (5000.0,) * 3, (50_000.0,) * 3,
                   source="high-speed mill: Hermle C 22 U datasheet v, a; jerk ours")


MACHINES = {"default": Machine.default, "hsm": high_speed_mill}


def window(pos: np.ndarray, first: np.ndarray, near: float = 2e-6) -> tuple[int, int]:
    """(start, end): the last period at rest at the program's first point, the last
    period the position changes."""
    moving = np.abs(np.diff(pos, axis=0)).max(1) > QUANTUM
    at = np.flatnonzero(np.linalg.norm(pos - first, axis=1) < near)
    if not len(at):
        raise RuntimeError("the run never reached the program's first point")
    start = int(at[0])
    while start < len(moving) and not moving[start]:
        start += 1
    return start, int(np.flatnonzero(moving)[-1]) + 1


def last_move(program) -> tuple[np.ndarray, np.ndarray]:
    """The ends (3,) of the program's final move (the last link's last move)."""
    pts = np.asarray(program.segments[-1].points, float)
    return pts[-2], pts[-1]


def trapezoid(length: float, v: float, a: float) -> float:
    """Seconds of a straight move of ``length`` mm from rest to rest at v, a."""
    return 2 * math.sqrt(length / a) if length < v * v / a else length / v + v / a


def measure(pos, first, ref: PathReference, m: Machine, last) -> dict:
    """Cycle time, time on the last move, true contour error and violations (mm, s)."""
    start, end = window(pos, first)
    run = pos[start:end + 1]
    err = ref.distance(run)
    a, b = last
    ab = b - a
    t = np.clip(((run - a) @ ab) / (ab @ ab), 0, 1)
    off = np.flatnonzero(np.linalg.norm(run - (a + t[:, None] * ab), axis=1) > 1e-3)
    on_last = len(run) - 1 - (int(off[-1]) if len(off) else 0)   # all on it: a one-line run
    out = {"cycle_time_s": (end - start) * m.period, "last_s": on_last * m.period,
           "contour_max_mm": float(err.max()),
           "contour_p99_mm": float(np.percentile(err, 99))}
    w = pos[max(start - 3, 0):end + 4]
    out.update({k.replace("_peak_share", "_share"): x for k, x in violations(w, m).items()})
    return out


def ngc_text(program, feed: float, p: float) -> str:
    """The program's own G-code with ``G64 P p`` and every F word set to ``feed``."""
    text = program_ngc(program, blend=p, tolerance=NGC_TOLERANCE)
    text = re.sub(r"^F[0-9.]+$", f"F{feed:.3f}", text, flags=re.MULTILINE)
    # the writer's prelude (G0 Z, G0 X Y to the first point) would blend into the first
    # link: a 1 ms dwell makes the run start at rest on the first point, as the stream does
    return re.sub(r"^(G0 X[^\n]*)$", r"\1\nG4 P0.001", text, count=1, flags=re.MULTILINE)


def dense_cut(piece, ref, program, part, machine: Machine, tol: float) -> np.ndarray:
    """(n, 3) a cut's points within ``tol`` mm of its exact path (see the module doc)."""
    if isinstance(ref, Arc):
        h = 2 * math.acos(1 - tol / ref.r)   # rad per chord: sag = tol
        t = np.linspace(0, ref.span, math.ceil(ref.span / h) + 1)
        return ref.c + ref.r * (np.cos(t)[:, None] * ref.e1 + np.sin(t)[:, None] * ref.e2)
    if not isinstance(ref, Offsets):
        return np.asarray(piece.points)[[0, -1]]
    one = replace(program, segments=[program.cuts[piece.cut]])
    fine = stream_program(one, replace(machine, period=DENSE_PERIOD), stepper_factory(part),
                          feed=DENSE_FEED, planned=False).positions
    pts = fine[simplify(fine, tol / 2)]
    if isinstance(ref, Guided):   # a pass on a free-form face: the kernel's points as they
        return pts                # are (each moved by Newton on OCCT would take hours)
    off = ref.distance(pts) > tol / 4   # the kernel's few points off its path
    if off.any():
        pts[off] = [ref.on_path(p) for p in pts[off]]
    return pts


def dense_ngc(program, part, ref: PathReference, machine: Machine, feed: float,
              tol: float = EQUAL_TOL) -> str:
    """G-code within ``tol`` mm of the exact path: cuts by ``dense_cut`` within half of it,
    links' moves as written (G0 for a rapid), every feed ``feed``, ``G64 P`` half of it,
    7 decimals."""
    xyz = lambda p: "X{:.7f} Y{:.7f} Z{:.7f}".format(*p)
    first = program.segments[0].points[0]
    lines = ["%", "G17 G21 G40 G90 G94", f"G64 P{tol / 2:.7f}", f"G0 Z{first[2]:.7f}",
             f"G0 X{first[0]:.7f} Y{first[1]:.7f}", "G4 P0.001", f"F{feed:.3f}"]
    dense = {pc.cut: dense_cut(pc, r, program, part, machine, tol / 2)
             for pc, r in zip(ref.pieces, ref.refs) if pc.cut is not None}
    k = 0
    for seg in program.segments:
        if seg.kind == "cut":
            lines += [f"G1 {xyz(p)}" for p in dense[k][1:]]
            k += 1
            continue
        for rapid, p in zip(seg.rapid, seg.points[1:]):
            lines.append(f"{'G0' if rapid else 'G1'} {xyz(p)}")
    return "\n".join(lines + ["M2", "%", ""])


def long_programs(folder: Path, shared: Path | None):
    """The long free-form programs (name, part, program): a raster finish of the free-form
    slab (R 3, stepover 1: about 56 000 points), a waterline program of the same face
    (R 3, stepdown 1), and, with ``shared``, the whole-part pencil of the L-bracket (R 3)."""
    import cadcnc
    from benchmarks.pace.bench_pace import slab_case

    path, job = slab_case(str(folder))
    part = cadcnc.load_step(path)
    yield "finish-slab free-form raster R 3 stepover 1", part, cadcnc.run(part, job)
    top = job.operation.faces
    yield "waterline-slab free-form R 3 stepdown 1", part, cadcnc.run(part, replace(
        job, operation=cadcnc.Waterline(top, 1.0)))
    if shared is not None:
        part = cadcnc.load_step(shared / "bug3883_xr2-ct-214_l-bracket.stp")
        yield "pencil-bracket whole part R 3", part, cadcnc.run(part, cadcnc.Job(
            cadcnc.Tool(3.0), 1500.0, 0.004, cadcnc.Pencil(), source=part.source))


def run_all(out: Path, machines: list[str], only: list[str] | None = None,
            cases=None) -> list[dict]:
    """Every case of ``cases`` (default: the three programs; ``only``: these programs,
    the other rows of results.json kept)."""
    done = out / "results.json"
    rows = [r for r in json.loads(done.read_text()) if not r["program"].startswith(
        tuple(only)) or r["machine"] not in machines] if only and done.exists() else []
    for name, part, program in (programs() if cases is None else cases):
        if only and not name.startswith(tuple(only)):
            continue
        tag, first, last = name.split()[0], program.segments[0].points[0], last_move(program)
        for mname in machines:
            m = MACHINES[mname]()
            t0 = time.monotonic()
            s = stream_program(program, m, stepper_factory(part), feed=FEED)
            ref = PathReference(s.plan.pieces, program, part)
            own = ref.stream_error(s.positions, s.rows)
            bound = va_bound(program, m, FEED)
            L = float(np.linalg.norm(last[1] - last[0]))
            d = (last[1] - last[0]) / L
            v = min(np.asarray(m.max_velocity) / np.maximum(np.abs(d), 1e-300))
            a = min(np.asarray(m.max_acceleration) / np.maximum(np.abs(d), 1e-300))
            full = trapezoid(L, v, a)
            print(f"{name} on {mname}: {ref.kinds()}, bound {bound:.3f} s, last move "
                  f"{L:.2f} mm: {full:.3f} s at a, {trapezoid(L, v, a / 2):.3f} s at a/2 "
                  f"({time.monotonic() - t0:.1f} s)", flush=True)
            base = {"program": name, "machine": mname, "feed": FEED, "bound_s": bound,
                    "last_full_s": full, "last_half_a_s": trapezoid(L, v, a / 2)}
            h = run_hal_loop(s.positions, m, limits="machine")

            def keep(method: str, pos: np.ndarray, extra: dict) -> None:
                """Measure one run and save it at once (a later run may fail or hang)."""
                np.save(out / f"{tag}_{mname}_{method.replace(' ', '_')}.npy", pos)
                row = {**base, "method": method, **measure(pos, first, ref, m, last), **extra}
                rows.append(row)
                print(line(row), flush=True)
                (out / "results.json").write_text(json.dumps(rows, indent=1))

            keep("stream", h.executed, {"clipped": h.clipped, "underruns": h.underruns,
                                        "planned_s": s.cycle_time,
                                        "own_max_mm": float(own.max()),
                                        "own_p99_mm": float(np.percentile(own, 99))})
            texts = [(f"LinuxCNC P{p:g}", lambda p=p: ngc_text(program, FEED, p)) for p in PS]
            equal = max(EQUAL_TOL, float(own.max()))   # the stream's own error
            base["equal_tol_mm"] = equal
            texts.append(("LinuxCNC equal", lambda: dense_ngc(program, part, ref, m, FEED,
                                                              equal)))
            for method, make in texts:
                text = make()
                n = text.count("\n")
                ngc = out / f"{tag}_{mname}_{method.split()[1]}.ngc"
                ngc.write_text(text)
                try:
                    if n > SAMPLE_DEPTH:   # about a line a period: more than the sampler holds
                        raise HalError(f"{n} lines: LinuxCNC runs about one a period, past "
                                       f"the sampler's {SAMPLE_DEPTH} periods; not run")
                    r = run_ngc(ngc, m, timeout=600 + n / 200)
                except HalError as e:   # recorded, not hidden: the row says why
                    print(f"  {method} failed: {e}", flush=True)
                    rows.append({**base, "method": method, "error": str(e).splitlines()[0],
                                 "lines": n})
                    (out / "results.json").write_text(json.dumps(rows, indent=1))
                    continue
                keep(method, r.positions, {"error": r.error, "lines": n})
    return rows


def remeasure(out: Path) -> list[dict]:
    """The rows of ``results.json`` measured again from the saved positions (no run)."""
    rows = json.loads((out / "results.json").read_text())
    for name, part, program in programs():
        first, last = program.segments[0].points[0], last_move(program)
        for mname, make in MACHINES.items():
            todo = [r for r in rows if r["program"] == name and r["machine"] == mname
                    and "cycle_time_s" in r]
            if not todo:
                continue
            m = make()
            s = stream_program(program, m, stepper_factory(part), feed=FEED)
            ref = PathReference(s.plan.pieces, program, part)
            for r in todo:
                pos = np.load(out / f"{name.split()[0]}_{mname}_"
                                    f"{r['method'].replace(' ', '_')}.npy")
                r.update(measure(pos, first, ref, m, last))
                print(line(r), flush=True)
    (out / "results.json").write_text(json.dumps(rows, indent=1))
    return rows


def line(r: dict) -> str:
    return (f"{r['program'][:8]:8s} {r['machine']:7s} {r['method']:16s} T {r['cycle_time_s']:7.3f}"
            f" s (bound {r['bound_s']:.3f}, last {r['last_s']:.3f}, full-a {r['last_full_s']:.3f})"
            f"  err max {r['contour_max_mm']:.2e} p99 {r['contour_p99_mm']:.2e} mm  over "
            f"v/a/j {r['v_over']}/{r['a_over']}/{r['j_over']} (peak {r['v_share']:.2f}/"
            f"{r['a_share']:.2f}/{r['j_share']:.1f}) "
            + " ".join(f"{k}={v}" for k, v in r.items() if k in
                       ("clipped", "underruns", "error", "planned_s", "own_max_mm", "lines")))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=Path("/tmp/cadcnc-compare"))
    ap.add_argument("--machines", nargs="+", choices=list(MACHINES), default=list(MACHINES))
    ap.add_argument("--only", nargs="+", metavar="PROGRAM",
                    help="run only these programs (corner, pencil, finish)")
    ap.add_argument("--remeasure", action="store_true",
                    help="measure the positions saved in --out again (no HAL, no LinuxCNC)")
    ap.add_argument("--long", action="store_true",
                    help="the long free-form programs (long_programs) instead of the three")
    ap.add_argument("--shared", type=Path, help="the public parts' folder (--long: the "
                    "whole-part pencil of the L-bracket)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.remeasure:
        remeasure(args.out)
    else:
        run_all(args.out, args.machines, args.only,
                long_programs(args.out, args.shared) if args.long else None)


if __name__ == "__main__":
    main()
