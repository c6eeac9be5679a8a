"""``--jobs N`` (issue 24): the same bytes whatever N, Ctrl-C and dead workers handled.

Ctrl-C: the command runs as a user runs it (a subprocess), so that the signal and the
exit code are the real ones. The same-bytes check runs the commands in this process
(``cadcnc.cli.app.main``, as conftest.cadcnc_cli): ``--jobs 2`` starts the same worker
processes there, without a second interpreter's imports per run. Workers start as forks
of the command (a command runs no other thread) unless told otherwise; this test process
runs xdist's threads, so the start method is set for each test.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import cadcnc
from cadcnc.core.errors import EXIT_INTERNAL, EXIT_INTERRUPTED, InputError
from cadcnc.geometry.part_bytes import part_blob, part_from_blob
from cadcnc.parallel.pool import START_ENV, WorkerError, map_ordered, start_method
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

pytestmark = pytest.mark.slow  # over about 5 s a test (pyproject.toml)


BOSS = str(FIXTURES / "finish_boss.step")
FINISH = ["finish", BOSS, "--faces", "6", "--radius", "3", "--stepover", "4"]
PENCIL = ["pencil", str(FIXTURES / "step_slot.step"), "--radius", "3"]


def cli(args, **kw) -> subprocess.Popen:
    env = {**os.environ, "CADCNC_JOBS": ""}  # the command's own default: every core
    return subprocess.Popen([sys.executable, "-m", "cadcnc.cli", *map(str, args)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def _parent_of(pid: str) -> int | None:
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, IndexError, ValueError):  # gone meanwhile
        return None


def descendants(pid: int) -> set[int]:
    """Every live process under ``pid`` (workers are grandchildren: a fork server's)."""
    parent = {int(p): _parent_of(p) for p in os.listdir("/proc") if p.isdigit()}
    out, todo = set(), [pid]
    while todo:
        mine = todo.pop()
        kids = {c for c, pp in parent.items() if pp == mine}
        out |= kids
        todo += kids
    return out


@pytest.mark.parametrize("command", [FINISH, PENCIL], ids=["finish", "pencil"])
def test_the_outputs_are_the_same_bytes_whatever_the_jobs(command, tmp_path, monkeypatch):
    monkeypatch.setenv(START_ENV, "fork")   # a command's own (test_fork_when_no_thread_runs)
    files = {}
    for n in (1, 2):
        outs = [tmp_path / f"p{n}.json", tmp_path / f"p{n}.ngc"]
        cadcnc_cli(*command, "--jobs", n, *[a for o in outs for a in ("-o", o)], check=0)
        files[n] = [o.read_bytes() for o in outs]
    assert files[1] == files[2]


def test_ctrl_c_stops_every_worker_and_writes_nothing(tmp_path):
    out = tmp_path / "p.json"
    run = cli([*FINISH[:-1], "1", "--jobs", "2", "-o", out])
    deadline = time.monotonic() + 120
    while len(descendants(run.pid)) < 2 and time.monotonic() < deadline:  # 2 forked workers
        time.sleep(0.1)
    workers = descendants(run.pid)
    assert len(workers) >= 2 and run.poll() is None
    run.send_signal(signal.SIGINT)
    _, err = run.communicate(timeout=60)
    assert run.returncode == EXIT_INTERRUPTED, err
    assert err.strip().splitlines()[-1] == "cadcnc: interrupted", err  # no teardown noise
    alive, deadline = workers, time.monotonic() + 30  # a worker's own teardown
    while alive and time.monotonic() < deadline:      # (OCCT, numba) takes about a second
        time.sleep(0.2)
        alive = {p for p in workers if Path(f"/proc/{p}").exists()}
    assert not alive and not out.exists() and list(tmp_path.iterdir()) == []


def _die(part, task):
    if task == 1:
        os.kill(os.getpid(), signal.SIGKILL)
    return len(part)


@pytest.mark.parametrize("method", ["fork", "forkserver"])
def test_a_dead_worker_is_an_error_not_a_hang(method, monkeypatch):
    monkeypatch.setenv(START_ENV, method)
    part = cadcnc.load_step(FIXTURES / "step_block.step")
    t0 = time.monotonic()
    with pytest.raises(WorkerError, match="a worker process died during task") as err:
        map_ordered(_die, [0, 1, 2, 3], part=part, jobs=2, build=part_from_blob,
                    build_args=lambda: part_blob(part))
    assert err.value.exit_code == EXIT_INTERNAL and time.monotonic() - t0 < 120


@pytest.mark.parametrize("method", ["fork", "forkserver"])
def test_tasks_come_back_in_order_from_the_part_in_each_worker(method, monkeypatch):
    monkeypatch.setenv(START_ENV, method)   # a copy of the part, or one rebuilt from bytes
    part = cadcnc.load_step(FIXTURES / "step_slot.step")
    got = map_ordered(_kind, list(range(1, len(part) + 1)), part=part, jobs=2,
                      build=part_from_blob, build_args=lambda: part_blob(part))
    assert got == [part.face(n).kind for n in range(1, len(part) + 1)]


def _kind(part, n):
    return part.face(n).kind


THREADED = ("import threading, time; from cadcnc.parallel.pool import start_method; "
            "print(start_method()); threading.Thread(target=time.sleep, args=(2,)).start(); "
            "print(start_method())")


def test_fork_when_no_thread_runs_and_the_server_when_one_does():
    env = {k: v for k, v in os.environ.items() if k != START_ENV}
    out = subprocess.run([sys.executable, "-c", THREADED], env=env, check=True,
                         capture_output=True, text=True).stdout.split()
    assert out == ["fork", "forkserver"]


def test_the_start_method_can_be_chosen_and_a_bad_one_is_refused(monkeypatch):
    monkeypatch.setenv(START_ENV, "spawn")
    assert start_method() == "spawn"
    monkeypatch.setenv(START_ENV, "thread")
    with pytest.raises(InputError, match="CADCNC_START_METHOD='thread': one of .*fork"):
        start_method()
