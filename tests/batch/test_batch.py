"""``cadcnc batch`` (issue 25) on Dask, loopback only: the embedded local cluster, and a
separately started ``dask scheduler`` with two ``dask worker`` processes (booted by a
module fixture while the other tests run, torn down after).

Shown: every part's status listed; a failing part (not a STEP file) does not stop the
others; the outputs are the bytes ``cadcnc pencil`` writes for the part alone; a re-run
skips unchanged parts without starting a cluster; a worker killed while it runs a part
has the part run again elsewhere, and the summary says so; bad job files are refused
before any work, naming the line and the key.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

pytestmark = pytest.mark.slow  # over about 5 s a test (pyproject.toml)

GOOD = ("step_block", "fillet_block")
JOB = """# two good parts and a broken one
parts = ["*.step"]
outputs = [".json", ".ngc"]

[options]
radius = 3
feed = 1500

[[operations]]
command = "pencil"
side = "climb"
"""
BOOT_S = 120.0   # the loaded 2-core machine: a worker imports OCCT and numba


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module", autouse=True)
def cluster():
    """``tcp://127.0.0.1:PORT``: a dask scheduler and two one-thread workers (nannies),
    started now so that they boot while the first tests run."""
    port = _free_port()
    bin_ = Path(sys.executable).parent
    common = ["--no-dashboard", "--dashboard-address", "127.0.0.1:0"]
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    procs = [subprocess.Popen([bin_ / "dask", "scheduler", "--host", "127.0.0.1", "--port",
                               str(port), *common], **quiet)]
    address = f"tcp://127.0.0.1:{port}"
    procs += [subprocess.Popen([bin_ / "dask", "worker", address, "--host", "127.0.0.1",
                                "--nthreads", "1", "--preload", "cadcnc.batch.task",
                                *common], **quiet) for _ in range(2)]
    yield address
    for p in procs:   # each its own session: a nanny and the worker it started, at once
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
    for p in procs:
        p.wait(timeout=60)


def _folder(tmp_path: Path, job: str = JOB, broken: bool = True) -> Path:
    for name in GOOD:
        shutil.copy(FIXTURES / f"{name}.step", tmp_path / f"{name}.step")
    if broken:
        (tmp_path / "broken.step").write_text("not a STEP file\n")
    (tmp_path / "jobs.toml").write_text(job)
    return tmp_path / "jobs.toml"


def _summary(jobs: Path) -> dict:
    data = json.loads((jobs.parent / "jobs-out" / "summary.json").read_text())
    return {r["part"]: r for r in data["records"]}


@pytest.fixture(scope="module")
def embedded(tmp_path_factory):
    """(job file, run): the batch on the embedded cluster (one worker: the cheapest)."""
    jobs = _folder(tmp_path_factory.mktemp("embedded"))
    return jobs, cadcnc_cli("batch", jobs, "--workers", "1")


def test_every_part_listed_and_a_failing_part_survives(embedded):
    jobs, run = embedded
    assert run.returncode == 6, run.stderr     # some parts failed: partial
    by_part = _summary(jobs)
    assert sorted(by_part) == ["broken", *sorted(GOOD)]
    assert by_part["broken"]["exit"] == 2 and "not a STEP file" in by_part["broken"]["message"]
    for name in GOOD:
        r = by_part[name]
        assert (r["status"], r["exit"], r["attempts"]) == ("done", 0, 1), r
        assert r["cuts"] >= 1 and 0 < r["coverage"] <= 1 and r["seconds"] > 0
        assert 0 < r["cpu_seconds"]
        assert r["outputs"] == [f"{name}/pencil.json", f"{name}/pencil.ngc"]
    csv_rows = (jobs.parent / "jobs-out" / "summary.csv").read_text().splitlines()
    assert len(csv_rows) == 4 and csv_rows[0].startswith("part,operation,status,exit")
    for name in (*GOOD, "broken"):   # printed, and progress shown
        assert any(line.startswith(name) for line in run.stdout.splitlines()), run.stdout
    assert "3/3 done (0 skipped), 0 running, 1 failed" in run.stderr


def test_outputs_are_the_bytes_of_each_part_alone(embedded, tmp_path):
    jobs, _ = embedded
    for name in GOOD:
        step = str((jobs.parent / f"{name}.step").resolve())
        alone = tmp_path / name
        alone.mkdir()
        cadcnc_cli("pencil", step, "--radius", "3", "--feed", "1500", "--side", "climb",
                   "-o", alone / "p.json", "-o", alone / "p.ngc", "-q", check=0)
        for suffix in (".json", ".ngc"):
            batch = jobs.parent / "jobs-out" / name / f"pencil{suffix}"
            assert batch.read_bytes() == (alone / f"p{suffix}").read_bytes(), (name, suffix)


def test_rerun_skips_unchanged_parts_without_starting_a_cluster(embedded):
    jobs, _ = embedded
    (jobs.parent / "broken.step").rename(jobs.parent / "broken.txt")  # only the good ones
    before = {n: (jobs.parent / "jobs-out" / n / "pencil.json").stat().st_mtime_ns
              for n in GOOD}
    t0 = time.monotonic()
    run = cadcnc_cli("batch", jobs, check=0)
    assert time.monotonic() - t0 < 10.0   # no cluster started, nothing computed
    by_part = _summary(jobs)
    assert sorted(by_part) == sorted(GOOD)
    assert {r["status"] for r in by_part.values()} == {"skipped"}
    assert all(by_part[n]["cuts"] >= 1 for n in GOOD)
    assert before == {n: (jobs.parent / "jobs-out" / n / "pencil.json").stat().st_mtime_ns
                      for n in GOOD}
    assert "2/2 done (2 skipped)" in run.stderr


def test_job_hash_follows_the_part_options_and_outputs(tmp_path):
    import cadcnc
    from cadcnc.batch.records import job_hash
    from cadcnc.batch.task import BatchOperation, BatchPart

    step = tmp_path / "a.step"
    shutil.copy(FIXTURES / "step_block.step", step)

    def part(radius=3.0, outputs=("p.json",)):
        job = cadcnc.Job(cadcnc.Tool(radius), 1500, 0.004, cadcnc.Pencil(), source=str(step))
        return BatchPart(str(step), (BatchOperation("pencil", job, outputs),))

    h = job_hash(part())
    assert h == job_hash(part())
    assert h != job_hash(part(radius=2.0)) and h != job_hash(part(outputs=("p.ngc",)))
    step.write_bytes(step.read_bytes() + b"\n")
    assert h != job_hash(part())


def test_a_worker_killed_mid_run_is_retried_on_the_separate_cluster(cluster, tmp_path,
                                                                     embedded):
    """``cadcnc batch --scheduler``: the first worker to start a part is killed (SIGKILL)
    while it runs it; the part runs again, the batch completes, the summary reports it,
    and every output is the embedded run's."""
    from distributed import Client

    jobs = _folder(tmp_path)
    killed: list[int] = []

    def kill_first(event) -> None:
        if not killed:
            killed.append(event[1]["pid"])
            os.kill(event[1]["pid"], signal.SIGKILL)

    with Client(cluster, timeout=BOOT_S) as client:
        client.wait_for_workers(2, timeout=BOOT_S)
        client.subscribe_topic("cadcnc-batch", kill_first)
        done: dict = {}
        runner = threading.Thread(target=lambda: done.update(
            run=cadcnc_cli("batch", jobs, "--scheduler", cluster)))
        runner.start()
        runner.join(timeout=BOOT_S)
        client.unsubscribe_topic("cadcnc-batch")
    assert not runner.is_alive() and killed
    run = done["run"]
    assert run.returncode == 6, run.stderr
    by_part = _summary(jobs)
    retried = [r for r in by_part.values() if r["attempts"] > 1]
    assert len(retried) == 1 and f"pid {killed[0]} " in retried[0]["message"], by_part
    assert by_part["broken"]["exit"] == 2
    reference = embedded[0].parent / "jobs-out"
    for name in GOOD:   # the embedded run's outputs, but for the part's path they record
        assert by_part[name]["exit"] == 0 and by_part[name]["worker"] != ""
        mine, theirs = jobs.parent / "jobs-out" / name, reference / name
        assert (mine / "pencil.ngc").read_bytes() == (theirs / "pencil.ngc").read_bytes()
        texts = [(d / "pencil.json").read_text().replace(str((j.parent / f"{name}.step")
                                                             .resolve()), "PART")
                 for d, j in ((mine, jobs), (theirs, embedded[0]))]
        assert '"source":"PART"' in texts[0].replace(" ", "") and texts[0] == texts[1]


BAD_TOML = [
    ("unknown top key", 'parts = ["*.step"]\nwidgets = 3\n[[operations]]\ncommand = "pencil"\n'
     'radius = 3\n', 2, "widgets"),
    ("missing part", 'parts = ["step_block.step",\n  "nothere.step"]\n[[operations]]\n'
     'command = "pencil"\nradius = 3\n', 2, "parts[2]"),
    ("no part matches", 'parts = ["*.stp"]\n[[operations]]\ncommand = "pencil"\nradius = 3\n',
     1, "parts[1]"),
    ("unknown option", 'parts = ["*.step"]\n[[operations]]\ncommand = "pencil"\n'
     'radius = 3\nwobble = 2\n', 5, "operations[1].wobble"),
    ("abbreviated option", 'parts = ["*.step"]\n[[operations]]\ncommand = "pencil"\nrad = 3\n',
     4, "operations[1].rad"),
    ("bad choice", 'parts = ["*.step"]\n[options]\nradius = 3\n[[operations]]\n'
     'command = "pencil"\nside = "sideways"\n', 6, "operations[1].side"),
    ("bad value", 'parts = ["*.step"]\n\n[options]\nradius = -3\n[[operations]]\n'
     'command = "pencil"\n', 4, "options.radius"),
    ("unknown command", 'parts = ["*.step"]\n[[operations]]\ncommand = "polish"\n', 3,
     "operations[1].command"),
    ("bad output", 'parts = ["*.step"]\noutputs = [".json",\n ".txt"]\n[[operations]]\n'
     'command = "pencil"\nradius = 3\n', 3, "outputs[2]"),
    ("an output option", 'parts = ["*.step"]\n[[operations]]\ncommand = "pencil"\n'
     'radius = 3\noutput = "x.ngc"\n', 5, "operations[1].output"),
]


@pytest.mark.parametrize("case, text, line, key", BAD_TOML, ids=[c[0] for c in BAD_TOML])
def test_bad_toml_job_files_are_refused_before_any_work(tmp_path, case, text, line, key):
    jobs = _folder(tmp_path, text, broken=False)
    run = cadcnc_cli("batch", jobs, check=2)
    assert f"jobs.toml:{line}: {key}:" in run.stderr, run.stderr
    assert not (tmp_path / "jobs-out").exists()   # nothing done, no folder made


def test_bad_json_job_file_names_its_line_and_key(tmp_path):
    jobs = tmp_path / "jobs.json"
    shutil.copy(FIXTURES / "step_block.step", tmp_path / "step_block.step")
    jobs.write_text(json.dumps({"parts": ["step_block.step"], "options": {"radius": 3},
                                "operations": [{"command": "pencil"},
                                               {"command": "pencil", "name": "b",
                                                "sde": "climb"}]}, indent=2))
    run = cadcnc_cli("batch", jobs, check=2)
    line = next(k for k, text in enumerate(jobs.read_text().splitlines(), 1) if '"sde"' in text)
    assert f"jobs.json:{line}: operations[2].sde:" in run.stderr, run.stderr
    assert not (tmp_path / "jobs-out").exists()
