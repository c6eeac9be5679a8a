"""Run ``cadcnc path`` for one face pair and read what it wrote (coverage benchmark).

cadcnc is used only as a user would: its command line, one subprocess per run, with a
timeout. The JSON it writes is read in both formats: version 1 (``cadcnc-toolpath``, one
path, ``points``) and version 2 (``cadcnc-program``, ``segments`` of kind ``cut`` and
``link``; only cut segments count). Refusals are classified from the message.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

EXPECTED_CODES = {0, 2, 3, 4, 5, 6}  # anything else (or a traceback) is a crash

REASONS = [  # (reason, pattern in cadcnc's message), first match wins
    ("no feasible position (stretch finder)", re.compile(r"no feasible ball position")),
    ("no corner to cut (pencil)", re.compile(r"no corner to cut")),
    ("start off a face", re.compile(r"touches face \d+ outside the face|outside the face")),
    ("ball cuts the part (gouge gate)", re.compile(r"cuts into the part")),
    ("faces tangent at the start", re.compile(r"stopped at the start point \(tangent\)")),
    ("partial path", re.compile(r": partial: ")),
    ("no solid in the file", re.compile(r"holds no solid")),
    ("tangent edge", re.compile(r"tangent edge")),
    ("not a concave pair for cadcnc", re.compile(r"meet along a|not adjacent|no concave edge")),
    ("curvature tighter than the ball at the start",
     re.compile(r"stopped at the start point \(curvature\)")),
    ("no start tangency found", re.compile(r"no cutter position touching both surfaces")),
    ("other start failure", re.compile(r"start|tangency", re.I)),
]


def cadcnc_command() -> list[str]:
    """The cadcnc CLI of this interpreter's environment."""
    exe = os.path.join(os.path.dirname(sys.executable), "cadcnc")
    return [exe] if os.path.exists(exe) else [sys.executable, "-m", "cadcnc.cli"]


def classify(code: int | None, stderr: str) -> str:
    """'written', 'crash', 'timeout' or the refusal's reason."""
    if code is None:
        return "timeout"
    if "Traceback (most recent call last)" in stderr or code not in EXPECTED_CODES:
        return "crash"
    if code == 0:
        return "written"
    for reason, pattern in REASONS:
        if pattern.search(stderr):
            stop = re.search(r"partial: stopped on (\w+)", stderr)
            return f"{reason} ({stop.group(1)})" if reason == "partial path" and stop else reason
    return f"other (exit {code})"


def cut_polylines(data: dict) -> list[np.ndarray]:
    """The cut polylines (each (n, 3), mm) of a version 1 or version 2 path JSON."""
    if data.get("format") == "cadcnc-program" or "segments" in data:
        return [np.asarray(s["points"], float).reshape(-1, 3)
                for s in data.get("segments", []) if s.get("kind") == "cut"]
    return [np.asarray(data["points"], float).reshape(-1, 3)]


def period_seconds(period: str) -> float:
    """'4ms' / '250us' / '0.004' as seconds."""
    m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*(ms|us|s)?\s*", period)
    if not m:
        raise ValueError(f"period {period!r}")
    return float(m.group(1)) * {"ms": 1e-3, "us": 1e-6, "s": 1.0, None: 1.0}[m.group(2)]


def path_command(step: str, faces, radius: float, feed: float, period: str, out: str,
                 edge: int | None, via: str) -> list[str]:
    """The subprocess that writes the pair's path: the CLI, or (``via == "api"``) the
    program pipeline through ``coverage_run_pair.py`` (every stretch, gated per cut)."""
    if via == "api":
        return [sys.executable, os.path.join(os.path.dirname(__file__), "coverage_run_pair.py"),
                step, str(faces[0]), str(faces[1]), repr(radius), repr(feed),
                repr(period_seconds(period)), out]
    cmd = [*cadcnc_command(), "path", step, "--faces", str(faces[0]), str(faces[1]),
           "--radius", repr(radius), "--feed", repr(feed), "--period", period, "-o", out]
    return cmd + (["--edge", str(edge)] if edge is not None else [])


def run_path(step: str, faces: tuple[int, int], radius: float, feed: float, period: str,
             timeout: float, edge: int | None = None, via: str = "cli") -> dict:
    """One ``cadcnc path`` run: {"edge", "code", "outcome", "message", "seconds",
    "version", "polylines", "refused_polylines", "skipped", "gate_refused"} (polylines
    empty unless a file was written; the last three from version 2 files)."""
    refused_lines, skipped, gated = [], [], []
    with tempfile.TemporaryDirectory(prefix="cadcnc-cov-") as tmp:
        out = os.path.join(tmp, "path.json")
        cmd = path_command(step, faces, radius, feed, period, out, edge, via)
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
            code, stderr = proc.returncode, proc.stderr
        except subprocess.TimeoutExpired:
            code, stderr = None, f"timeout after {timeout} s"
        seconds = time.perf_counter() - t0
        outcome = classify(code, stderr)
        polylines, version = [], None
        if outcome == "written" and os.path.exists(out):
            with open(out) as fh:
                data = json.load(fh)
            version = data.get("version")
            polylines = cut_polylines(data)
            skipped = [f"edge {k.get('edge')}: {k.get('reason')}: {k.get('detail')}"[:300]
                       for k in data.get("skipped", [])]
            gated = [f"edge {k['edge']} stretch {k['stretch']}: {k['message']}"[:300]
                     for k in data.get("gate_refused", [])]
            refused_lines = [np.asarray(k["points"], float).reshape(-1, 3)
                             for k in data.get("gate_refused", [])]
        elif outcome == "written":
            outcome = "exit 0 without a file"
    message = " ".join(stderr.strip().splitlines()[-1:])[:2000]
    return {"edge": edge, "code": code, "outcome": outcome, "message": message,
            "seconds": round(seconds, 2), "version": version, "polylines": polylines,
            "refused_polylines": refused_lines, "skipped": skipped, "gate_refused": gated}


def run_faces(step: str, timeout: float) -> str:
    """What ``cadcnc faces --json`` makes of a file: "N concave pairs" or the refusal."""
    try:
        proc = subprocess.run([*cadcnc_command(), "faces", step, "--json"], capture_output=True,
                              text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout"
    outcome = classify(proc.returncode, proc.stderr)
    if outcome != "written":
        return outcome
    return f"{len(json.loads(proc.stdout).get('concave_pairs', []))} concave pairs"


def distance_to_polylines(points: np.ndarray, polylines: list[np.ndarray]) -> np.ndarray:
    """Distance (mm) from each of ``points`` (k, 3) to the nearest segment of the polylines."""
    best = np.full(len(points), np.inf)
    for line in polylines:
        if len(line) == 1:
            best = np.minimum(best, np.linalg.norm(points - line[0], axis=1))
            continue
        a, b = line[:-1], line[1:]
        ab = b - a
        den = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
        for chunk in range(0, len(points), 256):
            p = points[chunk:chunk + 256, None, :]
            t = np.clip(np.einsum("kij,ij->ki", p - a, ab) / den, 0.0, 1.0)
            d = np.linalg.norm(p - (a + t[..., None] * ab), axis=2).min(axis=1)
            best[chunk:chunk + 256] = np.minimum(best[chunk:chunk + 256], d)
    return best
