"""The stream fuzz: `cadcnc stream` on random machines and feeds, every exit 0 judged
independently of the planner and of the stream check.

    python -m benchmarks.reliability.fuzz_stream --trials 500 --out fuzz_stream.json

A draw: one of the fixtures' programs (PROGRAMS, computed once), a LinuxCNC INI with a
servo period of 10 us to 10 ms, velocity, acceleration and jerk limits over several
decades (log-uniform, per axis, in mm or inch; the jerk key present or missing, then
given with ``--jerk`` or not at all), and a feed (or the program's). The judge reads the
written ``.npy`` only: finite differences of the positions against the INI's limits
(1e-6 relative slack), the ends against the program's first and last points, and OCCT's
distance from the positions to the part (:mod:`cadcnc.testing.moves_judge`): no position
deeper than 1 um into the part's offset (R' - d <= 1 um), and every position near a cut on
it (d - R' <= 1 um). Every exit is one of the defined codes, nothing is written unless 0,
no traceback, and a draw either finishes or says something on stderr at least every 5 s.
The suite runs a few draws (tests/reliability/test_fuzz_stream.py).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import random
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from benchmarks import FIXTURES
from cadcnc.testing.moves_judge import boundary_distances

PROGRAMS = {   # name: (part, the command that writes the program)
    "corner": ("step_block.step", ["path", "--faces", "3", "8", "--radius", "3", "--start",
                                   "19.0919,-23.3345,11", "--end", "16.2635,-20.5061,11"]),
    "pencil": ("step_block.step", ["pencil", "--radius", "3"]),
    "boss": ("bspline_boss.step", ["path", "--faces", "4", "5", "--radius", "3"]),
}
DEFINED = {0, 2, 3, 5}
SLACK = 1e-6       # relative, on every limit
OFF_PATH = 1e-3    # mm: 1 um, into the offset or off a cut
SAMPLES = 400      # positions judged by OCCT per draw
SILENCE_S = 5.0
MAX_PERIODS = 300_000
"""Each draw's ``--max-periods``: a longer stream is refused before any work (exit 2); the
gate of a stream costs about 0.1 ms a period here, and 500 draws must end in an hour."""


class Stderr(io.TextIOBase):
    """stderr kept, and the longest silence between two writes measured."""

    def __init__(self):
        self.parts: list[str] = []
        self.last = time.monotonic()
        self.longest = 0.0
        self.lock = threading.Lock()

    def write(self, text: str) -> int:
        with self.lock:
            now = time.monotonic()
            self.longest = max(self.longest, now - self.last)
            self.last = now
            self.parts.append(text)
        return len(text)

    def text(self) -> str:
        return "".join(self.parts)


def cli(*args) -> tuple[int, str, float]:
    """(exit code, stderr, longest silence on stderr in s) of ``cadcnc ARGS`` here."""
    from cadcnc.cli import main

    err = Stderr()
    t0 = time.monotonic()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = main([str(a) for a in args])
        except SystemExit as e:
            code = e.code
    longest = max(err.longest, time.monotonic() - err.last) if err.parts else \
        time.monotonic() - t0
    return int(code or 0), err.text(), longest


def write_programs(folder: Path, names=tuple(PROGRAMS)) -> dict:
    """{name: program .json} of each program, written by its command into ``folder``."""
    out = {}
    for name in names:
        part, command = PROGRAMS[name]
        path = folder / f"{name}.json"
        code, err, _ = cli(command[0], FIXTURES / part, *command[1:], "-o", path, "-q")
        if code != 0:
            raise RuntimeError(f"{name}: exit {code}: {err}")
        out[name] = path
    return out


def draw_machine(rng: random.Random) -> dict:
    """A random machine: INI text, the --jerk option (or None), the limits in mm."""
    inch = rng.random() < 0.25
    unit = 25.4 if inch else 1.0
    period_ns = round(10 ** rng.uniform(4.0, 7.0))   # 10 us .. 10 ms
    v = [10 ** rng.uniform(0.0, 3.0) for _ in range(3)]           # 1 .. 1000 mm/s
    a = [10 ** rng.uniform(1.0, 4.5) for _ in range(3)]           # 10 .. 3e4 mm/s^2
    j = [10 ** rng.uniform(2.0, 7.0) for _ in range(3)]           # 100 .. 1e7 mm/s^3
    jerk_key = rng.random() < 0.6
    jerk = None if jerk_key or rng.random() < 0.15 else 10 ** rng.uniform(2.0, 7.0)
    text = [f"[EMCMOT]\nSERVO_PERIOD = {period_ns}\n[TRAJ]\nLINEAR_UNITS = "
            f"{'inch' if inch else 'mm'}\n"]
    for k, axis in enumerate("XYZ"):
        text.append(f"[AXIS_{axis}]\nMAX_VELOCITY = {v[k] / unit!r}\n"
                    f"MAX_ACCELERATION = {a[k] / unit!r}\n"
                    + (f"MAX_JERK = {j[k] / unit!r}\n" if jerk_key else ""))
    if not jerk_key:
        j = [jerk] * 3 if jerk is not None else None
    return dict(ini="".join(text), jerk=jerk, period=period_ns * 1e-9, limits=(v, a, j))


def draw(rng: random.Random, names) -> dict:
    machine = draw_machine(rng)
    feed = None if rng.random() < 0.3 else 10 ** rng.uniform(1.0, 4.3)   # 10 .. 20 000 mm/min
    return dict(program=rng.choice(list(names)), feed=feed, **machine)


def _segment_distance(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """(N,) distance from each point to the polyline (its straight chords)."""
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    out = np.full(len(points), np.inf)
    for lo in range(0, len(points), 256):
        p = points[lo:lo + 256, None, :]
        t = np.clip(((p - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0, 1)
        d = np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)
        out[lo:lo + 256] = d.min(axis=1)
    return out


def judge_positions(x: np.ndarray, period: float, limits, program, part,
                    samples: int = SAMPLES) -> list[str]:
    """What an exit-0 stream gets wrong (empty: nothing), by its positions alone."""
    bad = []
    if x.ndim != 2 or x.shape[1] != 3 or not np.isfinite(x).all():
        return [f"positions not a finite (N, 3) array: {x.shape}"]
    for order, (name, lim) in enumerate(zip(("velocity", "acceleration", "jerk"), limits), 1):
        if len(x) <= order:
            continue
        d = np.abs(np.diff(x, order, axis=0)).max(axis=0) / period ** order
        for axis, (got, most) in enumerate(zip(d, lim)):
            if got > most * (1 + SLACK):
                bad.append(f"{name} {'XYZ'[axis]} {got:.6g} over {most:.6g}")
    first, last = program.segments[0].points[0], program.segments[-1].points[-1]
    for what, row, want in (("first", x[0], first), ("last", x[-1], last)):
        if np.abs(row - np.asarray(want)).max() > 1e-9:
            bad.append(f"{what} position off the program's by "
                       f"{np.abs(row - np.asarray(want)).max():.3g} mm")
    pick = np.unique(np.linspace(0, len(x) - 1, min(samples, len(x))).round().astype(int))
    pts = x[pick]
    ball = float(program.job.offsets[0])
    d = boundary_distances(part, pts)
    if (ball - d).max() > OFF_PATH:
        bad.append(f"a position {ball - d.max():.3g} mm into the offset "
                   f"(max depth {(ball - d).max():.3g} mm)")
    near_cut = np.zeros(len(pts), bool)
    for seg in program.cuts:
        near_cut |= _segment_distance(pts, np.asarray(seg.points, float)) <= OFF_PATH
    if near_cut.any() and (d[near_cut] - ball).max() > OFF_PATH:
        bad.append(f"a cut position {(d[near_cut] - ball).max():.3g} mm off the path")
    return bad


def judged(d: dict, programs: dict, parts: dict, folder: Path, run=cli,
           samples: int = SAMPLES, max_periods: int = MAX_PERIODS) -> dict:
    """Run one draw and judge it: {exit, stderr, silence, bad, ok}."""
    from cadcnc.io.program_json import read_program

    ini, out = folder / "machine.ini", folder / "s.npy"
    ini.write_text(d["ini"])
    args = ["stream", programs[d["program"]], "--machine", ini, "-o", out,
            "--max-periods", str(max_periods)]
    if d["jerk"] is not None:
        args += ["--jerk", f"{d['jerk']!r}"]
    if d["feed"] is not None:
        args += ["--feed", f"{d['feed']:.6g}"]
    code, err, silence = run(*args)
    bad = []
    if code not in DEFINED or "Traceback" in err:
        bad.append(f"exit {code}")
    if silence > SILENCE_S + 1.0:
        bad.append(f"silent for {silence:.1f} s")
    if code == 0:
        program = read_program(programs[d["program"]])
        bad += judge_positions(np.load(out), d["period"], d["limits"], program,
                               parts[PROGRAMS[d["program"]][0]], samples)
    elif out.exists():
        bad.append(f"exit {code} and a file written")
    if out.exists():
        out.unlink()
    return dict(exit=code, stderr=err.strip()[-300:], silence=round(silence, 1), bad=bad,
                ok=not bad)


def main(argv=None) -> int:
    import cadcnc

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=500)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=Path("fuzz_stream.json"))
    ap.add_argument("--max-periods", type=int, default=MAX_PERIODS)
    a = ap.parse_args(argv)
    rng = random.Random(a.seed)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        programs = write_programs(Path(tmp))
        parts = {p: cadcnc.load_step(FIXTURES / p) for p, _ in PROGRAMS.values()}
        t0 = time.time()
        for k in range(a.trials):
            d = draw(rng, programs)
            t = time.time()
            try:
                r = judged(d, programs, parts, Path(tmp), max_periods=a.max_periods)
            except Exception as e:  # noqa: BLE001 - a traceback is a finding
                r = dict(exit=None, stderr=f"{type(e).__name__}: {e}", bad=["traceback"],
                         ok=False)
            results.append({**{k2: v for k2, v in d.items() if k2 != "ini"}, **r,
                            "seconds": round(time.time() - t, 2)})
            a.out.write_text(json.dumps(results, indent=1))
            print(f"{k + 1}/{a.trials} {d['program']} T {d['period'] * 1e3:.3g} ms: exit "
                  f"{r['exit']} {'ok' if r['ok'] else 'BAD ' + '; '.join(r['bad'])} "
                  f"({time.time() - t0:.0f} s)", flush=True)
            if r["exit"] == 130:   # Ctrl-C or SIGTERM reached the command: stop here
                break
    exits: dict = {}
    for r in results:
        exits[str(r["exit"])] = exits.get(str(r["exit"]), 0) + 1
    bad = [r for r in results if not r["ok"]]
    longest = max((r["seconds"] for r in results), default=math.nan)
    print(f"trials {len(results)}; exits {exits}; not ok {len(bad)}; longest draw "
          f"{longest:.0f} s")
    return 0 if not bad else 1


if __name__ == "__main__":
    sys.exit(main())
