"""What `cadcnc stream` promises since issue 36: positions checked against the machine's
limits before anything is written, the right part, work estimated and bounded, a
heartbeat, SIGTERM as Ctrl-C, stale HAL folders of dead runs removed."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import numpy as np
import pytest

from cadcnc.controller.hal.session import remove_stale
from cadcnc.core.work_limits import Ticker
from cadcnc.verification.stream_check import check_stream
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

BLOCK = FIXTURES / "step_block.step"
SHORT = ["--faces", "3", "8", "--radius", "3", "--start", "19.0919,-23.3345,11",
         "--end", "16.2635,-20.5061,11"]
LIMITS = ((10.0, 10.0, 10.0), (100.0, 100.0, 100.0), (1e4, 1e4, 1e4))


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    d = tmp_path_factory.mktemp("stream36")
    cadcnc_cli("path", BLOCK, *SHORT, "-o", d / "p.json", check=0)
    return d / "p.json"


def _ramp(v: float, n: int = 2000, period: float = 1e-3) -> np.ndarray:
    """X from 0 at speed v (mm/s), smooth start and stop (cosine), one row per period."""
    t = np.linspace(0.0, 1.0, n)
    x = v * (n - 1) * period * (t - np.sin(2 * np.pi * t) / (2 * np.pi))
    return np.column_stack([x, np.zeros(n), np.zeros(n)])


def test_a_stream_within_the_limits_passes_and_one_over_is_named():
    ok = _ramp(4.0)
    assert check_stream(ok, 1e-3, LIMITS, ok[0], ok[-1]).ok
    fast = _ramp(6.0)   # peaks at 12 mm/s
    got = check_stream(fast, 1e-3, LIMITS, fast[0], fast[-1])
    assert not got.ok and got.over["velocity"]["X"] > 0
    assert "velocity of axis X reaches 12" in got.problems[0]
    assert got.over["velocity"]["Y"] == 0


def test_slack_is_one_part_in_a_million():
    x = np.zeros((3, 3))
    x[1:, 0] = [1e-2 * (1 + 0.5e-6), 2e-2 * (1 + 0.5e-6)]
    lim = ((10.0,) * 3, (1e9,) * 3, (1e15,) * 3)
    assert check_stream(x, 1e-3, lim, x[0], x[-1]).ok
    x[1:, 0] = [1e-2 * (1 + 2e-6), 2e-2 * (1 + 2e-6)]
    assert not check_stream(x, 1e-3, lim, x[0], x[-1]).ok


def test_ends_and_non_finite_positions_fail():
    x = _ramp(1.0)
    got = check_stream(x, 1e-3, LIMITS, x[0] + [0, 0, 1e-6], x[-1])
    assert not got.ok and "first position is 1e-06 mm from the program's first" in got.problems[0]
    x[5, 1] = np.nan
    assert "position 5 is not finite" in check_stream(x, 1e-3, LIMITS, x[0], x[-1]).problems[0]


def test_a_stream_over_the_limits_exits_5_and_writes_nothing(program, tmp_path):
    """Finding 3: the summary showed a limit broken and the command exited 0 (the planner
    of the finding, at a 1 us period and jerk 1e12). Now: exit 0 only within every limit;
    else refused by the planner or by the check (exit 5), nothing written."""
    out = tmp_path / "s.npy"
    ini = tmp_path / "m.ini"
    ini.write_text("[EMCMOT]\nSERVO_PERIOD = 1000\n[TRAJ]\nLINEAR_UNITS = mm\n" + "".join(
        f"[AXIS_{a}]\nMAX_VELOCITY = 50\nMAX_ACCELERATION = 500\nMAX_JERK = 1e12\n"
        for a in "XYZ"))
    run = cadcnc_cli("stream", program, "--machine", ini, "-o", out, "--feed", "3000")
    if run.returncode == 0:   # the planner kept the limits: the check agrees
        x = np.load(out)
        d = [np.abs(np.diff(x, k, axis=0)).max(axis=0) / 1e-6 ** k for k in (1, 2, 3)]
        assert all((d[k] <= lim * (1 + 1e-6)).all() for k, lim in enumerate(
            ((50,) * 3, (500,) * 3, (1e12,) * 3)))
    else:   # refused by the planner itself or by the check: exit 5 either way
        assert run.returncode == 5, run.stderr
        assert not out.exists() and "Traceback" not in run.stderr


def test_check_refuses_what_the_planner_would_write(program, tmp_path, monkeypatch):
    """The check does not trust the planner: positions nudged past the velocity limit
    after planning are refused (exit 5), nothing written."""
    import cadcnc.pipeline.streaming as stream  # the names the stream run calls

    real = stream.stream_program

    def nudged(*args, **kwargs):
        s = real(*args, **kwargs)
        s.positions[len(s.positions) // 2:, 0] += 0.1   # a 0.1 mm jump in one period
        s.positions[-1] = real(*args, **kwargs).positions[-1]
        return s

    monkeypatch.setattr(stream, "stream_program", nudged)
    out = tmp_path / "s.txt"
    run = cadcnc_cli("stream", program, "-o", out)
    assert run.returncode == 5 and not out.exists(), run.stderr
    assert "velocity of axis X" in run.stderr


def test_the_wrong_part_is_named(program, tmp_path):
    """Finding 6: `stream corner.json --part pocket.step` said 'feed must be a number'."""
    run = cadcnc_cli("stream", program, "--part", FIXTURES / "pocket.step",
                     "-o", tmp_path / "s.npy")
    assert run.returncode == 2, run.stderr
    assert "does not lie on" in run.stderr and "computed on another part" in run.stderr
    assert "step_block.step" in run.stderr and "feed must be" not in run.stderr


def test_an_origin_far_outside_the_part_is_an_input_error(tmp_path):
    """Finding 8: --origin 1e300,0,0 gave exit 3 (no feasible ball position)."""
    run = cadcnc_cli("path", BLOCK, *SHORT[:5], "--origin", "1e300,0,0",
                     "-o", tmp_path / "p.json")
    assert run.returncode == 2, run.stderr
    assert "--origin 1e+300,0,0:" in run.stderr and "RuntimeWarning" not in run.stderr


def test_periods_are_estimated_and_bounded_before_work(program, tmp_path, monkeypatch):
    """Finding 4: an estimate before the work, and a refusal over --max-periods (exit 2)
    before any position is computed."""
    import cadcnc.controller.cut_rows as cut_rows

    run = cadcnc_cli("stream", program, "-o", tmp_path / "s.npy")
    assert run.returncode == 0
    periods = int(run.stderr.split("cadcnc: stream: ")[1].split()[0])
    assert f"{periods} periods" in run.stdout

    def never(*args, **kwargs):
        raise AssertionError("no position of a stream over --max-periods is computed")

    monkeypatch.setattr(cut_rows, "follow", never)   # the kernel's loop over a cut
    run = cadcnc_cli("stream", program, "-o", tmp_path / "t.npy", "--max-periods",
                     str(periods // 2))
    assert run.returncode == 2 and "--max-periods" in run.stderr, run.stderr
    assert f"over the limit of {periods // 2}" in run.stderr
    assert not (tmp_path / "t.npy").exists()


def test_the_heartbeat_ticks_while_a_stage_runs():
    said = []
    with Ticker(said.append, "cadcnc: stream", every=0.05) as tick:
        tick.stage = "streaming 5 periods"
        time.sleep(0.3)
    n = len(said)
    time.sleep(0.15)
    assert n >= 3 and len(said) == n
    assert said[0].startswith("cadcnc: stream: streaming 5 periods, ")


def test_stale_folders_of_dead_runs_are_removed_never_a_live_ones(tmp_path):
    """Finding 5, after SIGKILL: the next run removes the folders of runs that are gone,
    by their process id, and leaves a live run's."""
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        gone = tmp_path / f"cadcnc-hal-{dead.pid}-abcd"
        kept = tmp_path / f"cadcnc-lcnc-{live.pid}-efgh"
        mine = tmp_path / f"cadcnc-hal-{os.getpid()}-ijkl"
        other = tmp_path / "cadcnc-hal-xyz"   # no process id: never guessed at
        for d in (gone, kept, mine, other):
            (d / "rtapi").mkdir(parents=True)
            (d / "stream.txt").write_text("0 0 0\n")
        assert remove_stale(tmp_path) == [gone]
        assert not gone.exists() and kept.exists() and mine.exists() and other.exists()
    finally:
        live.kill()
        live.wait()


@pytest.mark.slow   # about 7 s each: a fresh process loads OCCT
@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_long_stream_is_interrupted_cleanly(program, tmp_path, sig):
    """Finding 4 and 5: a long stream (--feed 1: about 350 000 periods) says how many
    periods it will compute before the work, and SIGINT or SIGTERM at any point gives
    exit 130 and leaves nothing behind."""
    import signal

    out = tmp_path / "s.npy"
    proc = subprocess.Popen([sys.executable, "-m", "cadcnc.cli", "stream", str(program),
                             "--feed", "1", "-o", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        first = proc.stderr.readline()
        assert "periods of 1 ms" in first and "to compute" in first, first
        time.sleep(1.0)
        proc.send_signal(getattr(signal, sig))
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_sigterm_while_an_output_set_is_written_leaves_no_temporary_file(tmp_path,
                                                                         monkeypatch):
    """Finding 5 for every command: SIGTERM while the temporary files are written is
    Ctrl-C (KeyboardInterrupt, exit 130): they are removed, the old outputs intact."""
    import signal

    import cadcnc.io.output_set as output_set

    old = tmp_path / "a.json"
    old.write_text("old")
    real = output_set.os.fdopen

    def fdopen(fd, mode):
        fh = real(fd, mode)
        os.kill(os.getpid(), signal.SIGTERM)
        return fh

    monkeypatch.setattr(output_set.os, "fdopen", fdopen)
    outputs = output_set.OutputSet([old, tmp_path / "b.csv"], (".json", ".csv"))
    with pytest.raises(KeyboardInterrupt):
        outputs.write({old: "new", tmp_path / "b.csv": "x"})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]
    assert old.read_text() == "old"
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL


def test_the_txt_is_checked_as_printed(program, tmp_path, monkeypatch):
    """The .txt's numbers, not only the array they were printed from: a text that breaks
    the limits is refused with its name, and neither file is written."""
    import cadcnc.pipeline.streaming as stream  # the names the stream run calls

    real = stream.stream_text

    def bumped(positions):
        rows = real(positions).splitlines()
        x, y, z = map(float, rows[len(rows) // 2].split())
        rows[len(rows) // 2] = f"{x + 0.05:.9f} {y:.9f} {z:.9f}"
        return "\n".join(rows) + "\n"

    monkeypatch.setattr(stream, "stream_text", bumped)
    npy, txt = tmp_path / "s.npy", tmp_path / "s.txt"
    run = cadcnc_cli("stream", program, "-o", npy, "-o", txt)
    assert run.returncode == 5, run.stderr
    assert f"{txt}: acceleration of axis X" in run.stderr
    assert not npy.exists() and not txt.exists()


@pytest.mark.slow   # about 10 s: the pocket's pencil program
def test_a_tiny_link_move_streams(tmp_path):
    """Found by issue 36's stream tests: `cadcnc stream` of this program ended in a
    traceback (OverflowError in FeedPlan.periods: a 1.4e-6 mm link move planned an
    infinite duration; fixed on main by the planner of issue 35)."""
    from cadcnc.cli.app import main

    prog = tmp_path / "pk.json"
    cadcnc_cli("pencil", FIXTURES / "pocket.step", "--radius", "2", "--allowance", "0.5",
               "-o", prog, "-q", check=0)
    assert main(["stream", str(prog), "-o", str(tmp_path / "pk.npy"), "-q", "--debug"]) == 0
