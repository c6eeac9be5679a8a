"""``python -m benchmarks profile``'s child (benchmarks/profile/): a command run under its
hooks reports the stages it names and the guard's OCCT calls, so that renaming a function
they wrap shows here rather than as a silently empty table."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from helpers.fixtures import FIXTURES

pytestmark = pytest.mark.slow  # runs the profile benchmark's children: about 15 s

ROOT = Path(__file__).resolve().parents[2]


def test_child_reports_stages_and_occt_calls(tmp_path):
    out = tmp_path / "report.json"
    subprocess.run([sys.executable, "-m", "benchmarks.profile.child", str(out), "--", "path",
                    str(FIXTURES / "bspline_boss.step"), "--faces", "4", "5", "--radius", "3",
                    "-q", "-o", str(tmp_path / "boss.ngc")], cwd=ROOT, check=True,
                   env=dict(os.environ, PYTHONPATH=str(ROOT)))
    report = json.loads(out.read_text())
    assert report["code"] == 0 and report["cpu"] > report["imports"] > 0.0
    for stage in ("load", "run", "stretches", "stepping", "guard.margin", "judge (gate)",
                  "outputs"):
        assert report["stages"][stage][1] >= 1, stage
    calls = [v[0] for k, v in report["occt"].items() if k.startswith("clearance:")]
    assert sum(calls) > 0
    assert report["callers"]
