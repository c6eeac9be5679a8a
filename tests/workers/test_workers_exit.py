"""Worker processes end with the process that started them, even before it is reaped.

A command that ends with ``os._exit`` (Ctrl-C, or any exit of the console script) stays a
zombie until its own parent reaps it, and a parent that reads the command's output waits
for the pipes to close first: a worker still waiting for a zombie to disappear would hold
them forever. Workers must treat a zombie parent as gone.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

from cadcnc.parallel.pool import process_alive

SCRIPT = """
import multiprocessing, os, sys
from cadcnc.parallel.pool import kept_pools, map_ordered
sys.path.insert(0, {tests!r})
from test_workers_exit import pause

part = "a part"                                                 # opaque to the pool
with kept_pools():
    map_ordered(pause, [0.0, 0.0], part=part, jobs=2, build=str, build_args=lambda: (part,))
    print(*sorted(p.pid for p in multiprocessing.active_children()), flush=True)
    os._exit(0)                                                 # no shutdown, as on a crash
"""


def pause(part, seconds):
    time.sleep(seconds)
    return seconds


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return "gone"


def test_a_zombie_is_not_alive():
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    deadline = time.monotonic() + 30
    while _state(child.pid) != "Z" and time.monotonic() < deadline:  # exited, not reaped
        time.sleep(0.05)
    os.kill(child.pid, 0)                  # a zombie still answers the signal-0 probe
    assert not process_alive(child.pid) and process_alive(os.getpid())
    child.wait()


def test_workers_end_when_their_parent_exits_unreaped():
    script = SCRIPT.format(tests=str(Path(__file__).parent))
    parent = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    workers = [int(p) for p in parent.stdout.readline().split()]
    assert len(workers) == 2
    deadline = time.monotonic() + 30
    while _state(parent.pid) != "Z" and time.monotonic() < deadline:
        time.sleep(0.05)
    assert _state(parent.pid) == "Z"       # exited, and we have not reaped it
    deadline = time.monotonic() + 20
    while any(_state(w) not in ("gone", "Z") for w in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    left = [w for w in workers if _state(w) not in ("gone", "Z")]
    parent.wait()
    assert not left, f"workers {left} outlived their parent"
