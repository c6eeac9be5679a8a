"""LinuxCNC's baseline run listens on no interface of this machine (issue 36, finding 7):
linuxcncrsh binds every interface of its own network namespace (``unshare --net``, only
``lo`` up), and the client reaches it there; nothing listens on its port out here."""

from __future__ import annotations

import os
import shutil
import subprocess
import threading
import time

import pytest

from cadcnc.controller.hal import linuxcnc_sim as sim
from cadcnc.controller.machine import Machine

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(shutil.which("linuxcnc") is None or shutil.which("ss") is None,
                       reason="needs linuxcnc-uspace and ss"),
    pytest.mark.skipif(os.geteuid() != 0, reason="a network namespace needs root"),
]


def test_linuxcncrsh_listens_in_its_own_namespace_only(tmp_path, monkeypatch):
    ngc = tmp_path / "t.ngc"
    ngc.write_text("G21 G90 G17\nG0 X0 Y0 Z0\nG1 X5 Y2 Z-1 F600\nM2\n")
    port = sim._free_port()
    monkeypatch.setattr(sim, "_free_port", lambda: port)
    seen, stop = [], threading.Event()

    def watch() -> None:
        while not stop.is_set():
            out = subprocess.run(["ss", "-ltnH"], capture_output=True, text=True).stdout
            seen.extend(line for line in out.splitlines() if f":{port} " in line)
            time.sleep(0.1)

    watcher = threading.Thread(target=watch)
    watcher.start()
    try:
        run = sim.run_ngc(ngc, Machine.default())
    finally:
        stop.set()
        watcher.join()
    assert run.error == "OK" and len(run.positions) > 100
    assert seen == []
