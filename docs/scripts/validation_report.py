"""Regenerate the results in docs/notes/validation.md and docs/img/deviation_vs_step.png.

    .venv/bin/python docs/scripts/validation_report.py

Runs every concave pair of every fixture (fixtures/fixtures.json) at steps 0.1, 0.2, 0.5
and 1 mm (period 4 ms, radius 3 mm, or 1.5 mm where the pair cannot take a 3 mm ball),
verifies each path with :func:`cadcnc.verification.verify`, and rewrites the part of
docs/notes/validation.md between the ``results`` markers. Deterministic up to OCCT timings.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import cadcnc  # noqa: E402
from cadcnc.ops.path.pair_path import intersection_path
from cadcnc.verification import verify  # noqa: E402

STEPS = (0.1, 0.2, 0.5, 1.0)
PERIOD = 0.004
SMALL = {"narrow_slot": 1.5}  # 4 mm slot, r=2 hole: a 3 mm ball does not fit
START, END = "<!-- results:start -->", "<!-- results:end -->"


def pairs():
    side = json.loads((ROOT / "fixtures" / "fixtures.json").read_text())
    for name in sorted(side):
        for p in side[name]["pairs"]:
            if p["class"] == "concave":
                yield name, side[name]["file"], *p["faces"]


def fmt(x):
    if x is None or not math.isfinite(x):
        return "-"
    return "0" if x == 0 else (f"{x:.1e}" if abs(x) < 0.01 else f"{x:.3g}")


def run():
    rows, curves, parts = [], {}, {}
    for name, file, i, j in pairs():
        part = parts.setdefault(name, cadcnc.load_step(ROOT / "fixtures" / file))
        radius = SMALL.get(name, 3.0)
        for f in STEPS:
            tp = intersection_path(part.face(i), part.face(j), radius=radius,
                                          feed=f / PERIOD * 60, period=PERIOD)
            if len(tp) < 2:
                rows.append((name, i, j, radius, f, None, tp))
                continue
            rep = verify(tp, part)
            rows.append((name, i, j, radius, f, rep, tp))
            dev = max(rep.max_overcut_mm, rep.max_undercut_mm)
            curves.setdefault((name, i, j), []).append((f, dev, tp.worst_predicted_mm))
    return rows, curves


def order(points):
    """Least-squares slope of log(deviation) against log(step), where measurable."""
    pts = [(f, d) for f, d, _ in points if d > 1e-9]
    if len(pts) < 3:
        return None
    x, y = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(x, y, 1)[0])


def table(rows, curves) -> str:
    out = ["| fixture | faces | R mm | f mm | points | max over-cut | max under-cut | "
           "centres to OCCT | Hausdorff (polyline) | eq. 16 bound | exceeded eq. 16 | "
           "coverage | stop | other faces hit | order |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, i, j, radius, f, rep, tp in rows:
        if rep is None:
            out.append(f"| {name} | {i}/{j} | {radius:g} | {f:g} | {len(tp)} | - | - | - | - | "
                       f"- | - | - | {tp.stop_reason} | - | - |")
            continue
        exceeded = sum(t.eq16_exceeded_abs or 0 for t in rep.theory)
        hits = ", ".join(f"{h.face} ({fmt(h.depth_mm)})" for h in rep.whole_part_hits
                         if not h.followed) or "none"
        o = order(curves.get((name, i, j), [])) if f == STEPS[-1] else None
        out.append(
            f"| {name} | {i}/{j} | {radius:g} | {f:g} | {len(tp)} | {fmt(rep.max_overcut_mm)} | "
            f"{fmt(rep.max_undercut_mm)} | {fmt(rep.reference.points_max_mm)} | "
            f"{fmt(rep.hausdorff_mm)} | {fmt(tp.worst_predicted_mm)} | {exceeded} | "
            f"{rep.coverage:.4f} | {tp.stop_reason} | {hits} | "
            f"{'' if o is None else f'{o:.2f}'} |")
    return "\n".join(out)


def plot(curves, path: Path):
    fig, ax = plt.subplots(figsize=(7.5, 5.5))
    for (name, i, j), pts in sorted(curves.items()):
        f = np.array([p[0] for p in pts])
        d = np.array([p[1] for p in pts])
        if (d > 1e-9).sum() < 3:
            continue  # planes and exact cases: deviation is round-off
        ax.loglog(f, d, "o-", label=f"{name} {i}/{j}")
    f = np.array(STEPS)
    ax.loglog(f, 3e-3 * f ** 2, "k--", label="slope 2 (f$^2$)")
    ax.loglog(f, 2e-5 * f ** 4, "k:", label="slope 4 (f$^4$)")
    ax.set_xlabel("feed step f (mm)")
    ax.set_ylabel("max deviation from the offset surfaces (mm)")
    ax.set_title("Measured deviation against step (OCCT projection), R = 3 mm")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def main() -> int:
    rows, curves = run()
    plot(curves, ROOT / "docs" / "img" / "deviation_vs_step.png")
    md = ROOT / "docs" / "notes" / "validation.md"
    text = md.read_text()
    head, rest = text.split(START, 1)
    tail = rest.split(END, 1)[1]
    md.write_text(f"{head}{START}\n\n{table(rows, curves)}\n\n{END}{tail}")
    print(table(rows, curves))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
