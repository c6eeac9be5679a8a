"""The documentation's Python examples run as written (so the docs cannot rot)."""

from __future__ import annotations

import os
import re

from conftest import ROOT


def test_api_examples_run(monkeypatch):
    text = (ROOT / "docs" / "api.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    monkeypatch.chdir(ROOT)
    sent = []
    namespace = {"send_to_axes": sent.append}
    for block in blocks:
        exec(compile(block, "docs/api.md", "exec"), namespace)
    assert namespace["path"].stop_reason == "closed"
    assert (namespace["same"].points == namespace["path"].points).all()
    assert namespace["job"].step == 0.1 and namespace["same"].job.operation.faces == (4, 5)
    assert namespace["stepper"].stop_reason == "closed"
    assert len(sent) == namespace["stepper"].cycles
    assert os.path.exists(ROOT / "fixtures" / "bspline_boss.step")
