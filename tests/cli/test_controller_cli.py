"""`cadcnc stream` as a user runs it: formats, the gate before writing, Ctrl-C."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

BLOCK = FIXTURES / "step_block.step"
# 4 mm of the block's straight corner (faces 3 and 8): a short program, fast to gate
SHORT = ["--faces", "3", "8", "--radius", "3", "--start", "19.0919,-23.3345,11",
         "--end", "16.2635,-20.5061,11"]


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    d = tmp_path_factory.mktemp("stream")
    cadcnc_cli("path", BLOCK, *SHORT, "-o", d / "p.json", check=0)
    return d / "p.json"


def test_npy_and_txt_agree_and_gate_passes(program, tmp_path):
    npy, txt = tmp_path / "s.npy", tmp_path / "s.txt"
    run = cadcnc_cli("stream", program, "-o", npy, "-o", txt, "--feed", "10000", check=0)
    x = np.load(npy)
    assert x.ndim == 2 and x.shape[1] == 3 and x.dtype == np.float64
    lines = txt.read_text().splitlines()
    assert len(lines) == len(x)
    assert all(len(line.split()) == 3 and all(len(v.split(".")[1]) == 9 for v in line.split())
               for line in lines)
    assert np.abs(np.loadtxt(txt) - x).max() <= 5e-10
    assert f"{len(x) - 1} periods" in run.stdout and "max jerk" in run.stdout


def test_gate_refusal_writes_nothing(program, tmp_path):
    """The first link moved to start 3 mm inside the part: the stream's moves there gouge,
    the gate refuses them (exit 5) and nothing is written."""
    data = json.loads(program.read_text())
    link = data["segments"][0]
    assert link["kind"] == "link"
    cut_start = data["segments"][1]["points"][0]
    link["points"][0] = [cut_start[0], cut_start[1], cut_start[2] - 3.0]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    out = tmp_path / "s.npy"
    run = cadcnc_cli("stream", bad, "-o", out)
    assert run.returncode == 5 and not out.exists(), (run.returncode, run.stderr)
    assert "nothing written" in run.stderr


@pytest.mark.parametrize("where", ["cadcnc.pipeline.streaming.gate_program",
                                   "cadcnc.io.output_set.os.replace"])
def test_ctrl_c_leaves_no_file(program, tmp_path, monkeypatch, where):
    import cadcnc.io.output_set  # noqa: F401 - the module patched by name
    import cadcnc.pipeline.streaming  # noqa: F401

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(where, interrupt)
    run = cadcnc_cli("stream", program, "-o", tmp_path / "s.npy", "-o", tmp_path / "s.txt")
    assert run.returncode == 130 and "interrupted" in run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_long_stream_without_disk_room_is_exit_4_and_writes_nothing(program, tmp_path,
                                                                     monkeypatch):
    """A stream long enough for a scratch file, on a disk with no room for it: exit 4
    naming the folder and the size, no traceback, nothing written (the files of a stream
    in a scratch file: tests/pipeline/test_stream_files.py)."""
    import errno
    import os

    from cadcnc.core import scratch

    monkeypatch.setattr(scratch, "IN_MEMORY_ROWS", 100)

    def full(fd, offset, size):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "posix_fallocate", full)
    full_dir = tmp_path / "full"
    full_dir.mkdir()
    run = cadcnc_cli("stream", program, "-o", full_dir / "s.npy", "-q")
    assert run.returncode == 4, (run.returncode, run.stderr)
    assert run.stderr.startswith("cadcnc: error: the scratch file of the stream's positions, ")
    assert str(full_dir) in run.stderr and "No space left" in run.stderr
    assert "Traceback" not in run.stderr
    assert list(full_dir.iterdir()) == []


needs_hal = pytest.mark.skipif(shutil.which("halrun") is None,
                               reason="halrun not installed (apt install linuxcnc-uspace)")


@needs_hal
def test_hal_executes_the_planned_stream_unclipped(program, tmp_path):
    """--hal: the gated stream through streamer -> limit3 at the machine's limits ->
    sampler; every sample read back, no underrun, nothing clipped, executed = commanded."""
    out = tmp_path / "s.npy"
    run = cadcnc_cli("stream", program, "-o", out, "--feed", "10000", "--hal", check=0)
    n = len(np.load(out))
    assert f"HAL loop: {n} periods" in run.stdout, run.stdout
    assert "underruns within the program: 0;" in run.stdout
    assert f"samples clipped by limit3: 0 of {n} in the program" in run.stdout
    got = float(run.stdout.split("executed - commanded: max ")[1].split()[0])
    assert got <= 1e-6


@needs_hal
def test_a_constant_feed_stream_over_the_limits_is_refused_before_hal(program, monkeypatch):
    """At constant 10 000 mm/min the stream asks 167 mm/s of axes limited to 57 mm/s: the
    stream check refuses it before HAL starts (exit 5, nothing executed; limit3's clipping
    of such a stream: tests/controller/test_hal_loop.py)."""
    import cadcnc.controller.hal as hal

    def never(*args, **kwargs):
        raise AssertionError("HAL must not run a stream over the limits")

    monkeypatch.setattr(hal, "run_hal_loop", never)
    run = cadcnc_cli("stream", program, "--hal", "--constant-feed", "--feed", "10000")
    assert run.returncode == 5, (run.returncode, run.stdout, run.stderr)
    assert "velocity of axis" in run.stderr and "nothing written or executed" in run.stderr


def test_hal_that_cannot_start_is_exit_1_with_the_reason(program, monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))   # no halrun on it
    run = cadcnc_cli("stream", program, "--hal")
    assert run.returncode == 1 and "not on PATH: halrun" in run.stderr, run.stderr


def test_stream_needs_an_output_or_hal(program):
    run = cadcnc_cli("stream", program)
    assert run.returncode == 2 and "--hal" in run.stderr


def test_an_operation_streams_its_verified_program(tmp_path):
    """`pencil ... --stream OUT`: the program written and its stream beside it, from the
    program's first point to its last (exit 0)."""
    from cadcnc.io.program_json import read_program

    prog, npy = tmp_path / "p.json", tmp_path / "p.npy"
    run = cadcnc_cli("pencil", FIXTURES / "step_block.step", "--radius", "3", "-o", prog,
                     "--stream", npy, "-q")
    assert run.returncode == 0, run.stderr
    rows, program = np.load(npy), read_program(prog)
    np.testing.assert_allclose(rows[0], program.segments[0].points[0], atol=1e-9)
    np.testing.assert_allclose(rows[-1], program.segments[-1].points[-1], atol=1e-9)


@pytest.mark.parametrize("bad", ["-1", "nan", "inf", "1mm"])
def test_a_bad_blend_is_exit_2_without_traceback(program, tmp_path, bad):
    out = tmp_path / "s.npy"
    run = cadcnc_cli("stream", program, "-o", out, f"--blend={bad}")
    assert run.returncode == 2 and "--blend" in run.stderr, run.stderr
    assert "Traceback" not in run.stderr and not out.exists()


def test_blend_zero_streams_the_exact_corners(program, tmp_path):
    """``--blend 0``: the stream of the program's own moves, as the library streams it
    without blending."""
    import cadcnc
    from cadcnc.controller import Machine, stream_program
    from cadcnc.io.program_json import read_program
    from cadcnc.ops.stream_steppers import stepper_factory

    out = tmp_path / "s.npy"
    run = cadcnc_cli("stream", program, "-o", out, "--feed", "10000", "--blend", "0", "-q")
    assert run.returncode == 0, run.stderr
    prog = read_program(program)
    part = cadcnc.load_step(prog.job.source)
    exact = stream_program(prog, Machine.default(), stepper_factory(part), feed=10_000.0)
    assert np.load(out).tobytes() == exact.positions.tobytes()
