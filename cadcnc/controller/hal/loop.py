"""HAL in the loop: a per-period X Y Z stream executed by HAL's ``streamer`` and ``limit3``.

``run_hal_loop(stream, machine)`` writes ``stream_loop.hal`` for the machine's period and
limits, starts HAL (:class:`~.session.HalSession`), fills the streamer FIFO with
``halstreamer`` before anything moves, starts streamer and sampler in the same period, reads
the executed positions back with ``halsampler`` and unloads HAL, also on failure and on
Ctrl-C. Units: mm, s. The library imports no HAL: everything runs in subprocesses.
"""

from __future__ import annotations

import itertools
import string
import subprocess
import time
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ...core.errors import InputError
from ...core.scratch import rows_array
from ...core.work_limits import sigterm_as_interrupt
from ..stream import stream_text
from .session import HalError, HalInterrupted, HalSession, work_folder

SAMPLE_RES = 1e-9  # mm: halsampler prints 6 decimals of the µm the sampler holds
WIDE = 1e20  # limit3's own "no limit"
MAX_DEPTH = 2_000_000  # FIFO rows held in shared memory (~48 MB for the streamer)
BLOCK = 1 << 16  # rows checked, or sample lines read, at a time (a few MB)


@dataclass(frozen=True)
class HalLoopResult:
    """What HAL executed. Arrays are (M, 3) mm, one row per servo period from the start."""

    period: float  # s
    streamed: int  # periods in the program
    read: int  # samples read back (program plus tail)
    underruns: int  # streamer underruns between the first and last sample of the program
    overruns: int  # samples lost by the sampler (gaps in the sample numbers)
    commanded: np.ndarray  # streamer output, as sampled
    executed: np.ndarray  # limit3 output, as sampled
    clipped: int  # program samples where limit3 did not pass its input through (> SAMPLE_RES)
    clipped_tail: int  # the same after the program's last period (limit3 settling)
    command_error: float  # max |commanded - stream| over the program, mm
    tracking_error: float  # max |executed - stream| over the program, mm
    wall_time: float  # s, from the start gate to the last sample read

    @property
    def executed_error(self) -> float:
        """max |executed - commanded| over the program's samples, mm."""
        m = min(self.streamed, len(self.executed))
        return _max_gap(self.executed[:m], self.commanded[:m])

    @property
    def cycle_time(self) -> float:
        """The program's duration at the servo period, s."""
        return self.streamed * self.period


def write_stream_txt(stream: np.ndarray, path: Path) -> Path:
    """The ``.txt`` halstreamer reads for ``cfg=fff``: ``X Y Z`` per line, 9 decimals (mm),
    printed BLOCK rows at a time (:func:`~cadcnc.controller.stream.stream_text`)."""
    rows = np.asarray(stream, dtype=np.float64)
    with open(path, "w") as out:
        for a in range(0, len(rows), BLOCK):
            out.write(stream_text(rows[a:a + BLOCK]))
    return Path(path)


def read_stream(stream: Any) -> np.ndarray:
    """An (N, 3) float64 array from an array, a ``.npy`` (mapped, not read into memory)
    or a ``.txt`` stream; an array of float64 is used as it is."""
    if isinstance(stream, (str, Path)):
        p = Path(stream)
        try:
            arr = (np.load(p, mmap_mode="r") if p.suffix == ".npy"
                   else np.loadtxt(p, ndmin=2))
        except (OSError, ValueError) as e:
            raise InputError(f"cannot read the stream {p}: {e}") from None
    else:
        arr = stream
    arr = np.asarray(arr, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3 or len(arr) < 2 or not _finite(arr):
        raise HalError(f"a stream is an (N >= 2, 3) finite array of X Y Z mm; got {arr.shape}")
    return arr


def _finite(rows: np.ndarray) -> bool:
    """Whether every number of ``rows`` is finite (BLOCK rows at a time)."""
    return all(np.isfinite(rows[a:a + BLOCK]).all() for a in range(0, len(rows), BLOCK))


def _max_gap(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| over equal-shaped arrays (BLOCK rows at a time), 0 when empty."""
    return max((float(np.abs(a[k:k + BLOCK] - b[k:k + BLOCK]).max())
                for k in range(0, len(a), BLOCK)), default=0.0)


def hal_text(machine: Any, n_rows: int, *, limits: str = "machine", tail: int = 0) -> str:
    """The .hal file for ``machine`` (period s, max_velocity mm/s, max_acceleration mm/s²).

    ``limits='machine'`` sets each ``limit3`` to the axis's velocity and acceleration;
    ``'wide'`` leaves limit3's own 1e20 (it then passes every input through).
    """
    if limits not in ("machine", "wide"):
        raise HalError(f"limits is 'machine' or 'wide', not {limits!r}")
    period_ns = int(round(machine.period * 1e9))
    if period_ns < 50_000:
        raise HalError(f"servo period {machine.period} s is under 50 µs: not run here")
    v = machine.max_velocity if limits == "machine" else (WIDE,) * 3
    a = machine.max_acceleration if limits == "machine" else (WIDE,) * 3
    template = resources.files(__package__).joinpath("stream_loop.hal").read_text()
    return string.Template(template).substitute(
        period_ns=period_ns, stream_depth=min(n_rows + 16, MAX_DEPTH),
        sample_depth=min(n_rows + tail + 16, MAX_DEPTH),
        load_width_ns=3 * period_ns // 2,  # 2 or 3 periods (edge versions differ): >= 2
        **{f"maxv_{ax}": repr(float(x)) for ax, x in zip("xyz", v)},
        **{f"maxa_{ax}": repr(float(x)) for ax, x in zip("xyz", a)})


def run_hal_loop(stream: Any, machine: Any, *, limits: str = "machine",
                 tail: int | None = None, workdir: Path | None = None,
                 timeout: float | None = None, on_started=None) -> HalLoopResult:
    """Execute ``stream`` (N, 3 mm per period) in HAL at ``machine``'s period and limits.

    ``tail`` periods are sampled after the program (default 0.25 s) so a lagging limit3
    can be seen settling. ``timeout`` (s, wall) defaults to three times the run plus 30 s.
    ``on_started`` is called once the stream moves (for tests). Raises HalError, or
    HalInterrupted on Ctrl-C; HAL is unloaded in every case.
    """
    rows = read_stream(stream)
    n = len(rows)
    tail = int(round(0.25 / machine.period)) if tail is None else int(tail)
    total = n + tail
    timeout = 3 * total * machine.period + 30 if timeout is None else timeout
    text = hal_text(machine, n, limits=limits, tail=tail)
    with sigterm_as_interrupt(), work_folder("hal") as tmp:
        work = Path(workdir) if workdir is not None else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        txt = write_stream_txt(rows, work / "stream.txt")
        session = HalSession(text, work)
        started = 0.0
        try:
            session.start()
            out_path = work / "samples.txt"
            with open(txt, "rb") as src, open(work / "halstreamer.log", "wb") as log:
                feeder = session.spawn(["halstreamer", "-c", "0"], stdin=src,
                                       stdout=log, stderr=log)
            _prefill(session, feeder, min(n, MAX_DEPTH - 16), work)
            with open(out_path, "wb") as out, open(work / "halsampler.log", "wb") as log:
                reader = session.spawn(["halsampler", "-c", "0", "-t", "-n", str(total)],
                                       stdout=out, stderr=log)
            session.halcmd("sets", "cadcnc-start", "TRUE")
            started = time.monotonic()
            if on_started is not None:
                on_started()
            _wait(reader, started + timeout, "halsampler", work / "halsampler.log")
            wall = time.monotonic() - started
            result = _read_samples(out_path, rows, total, machine.period, wall,
                                   None if workdir is None else str(work))
        except KeyboardInterrupt:
            session.stop()
            done = int((time.monotonic() - started) / machine.period) if started else 0
            raise HalInterrupted(f"HAL run interrupted (Ctrl-C or SIGTERM; about {min(done, n)} of {n} "
                                 "periods executed); HAL unloaded") from None
        finally:
            problems = session.stop()
        if problems:
            raise HalError("HAL stopped uncleanly: " + "; ".join(problems))
    return result


def _prefill(session: HalSession, feeder: subprocess.Popen, want: int, work: Path) -> None:
    """Wait until the streamer FIFO holds ``want`` rows (or halstreamer has written all)."""
    deadline = time.monotonic() + 60
    while True:
        depth = int(session.get("streamer.0.curr-depth"))
        if depth >= want:
            return
        code = feeder.poll()
        if code is not None and code != 0:
            raise HalError(f"halstreamer failed (exit {code}): "
                           + (work / "halstreamer.log").read_text(errors="replace")[-500:])
        if time.monotonic() > deadline:
            raise HalError(f"streamer FIFO holds {depth} of {want} rows after 60 s")
        time.sleep(0.05)


def _wait(proc: subprocess.Popen, deadline: float, name: str, log: Path) -> None:
    """Wait for a helper to finish before ``deadline`` (monotonic s); HalError otherwise."""
    while proc.poll() is None:
        if time.monotonic() > deadline:
            raise HalError(f"{name} did not finish in time")
        time.sleep(0.05)
    if proc.returncode != 0:
        raise HalError(f"{name} exit {proc.returncode}: "
                       + log.read_text(errors="replace")[-500:])


def _read_samples(path: Path, rows: np.ndarray, total: int, period: float, wall: float,
                  folder: str | None) -> HalLoopResult:
    """The run's facts from halsampler's tagged lines (tag, commanded X Y Z µm, executed
    X Y Z µm, underruns; sample k is the program's row k), read BLOCK lines at a time: the
    commanded and executed positions go to (total, 3) arrays (a scratch file past
    :data:`~cadcnc.core.scratch.IN_MEMORY_ROWS`), the rest is counted on the way."""
    n = len(rows)
    cmd = rows_array(total, folder, "HAL's commanded positions")
    exe = rows_array(total, folder, "HAL's executed positions")
    read, columns = 0, 8
    tags, under = [0, 0], [0, 0]   # at the first sample and at the last (tags), or the
    # program's last (underruns)
    clipped = clipped_tail = 0
    command_error = tracking_error = 0.0
    with open(path) as lines:
        while True:
            block = list(itertools.islice(lines, BLOCK))
            if not block:
                break
            try:
                data = np.loadtxt(block, ndmin=2)
            except ValueError as e:
                raise HalError(f"halsampler's samples ({path.name}) do not read: {e}") from None
            if data.shape[1] != 8 or read + len(data) > total:
                columns = data.shape[1] if data.shape[1] != 8 else columns
                read += len(data)
                continue
            k = slice(read, read + len(data))
            cmd[k], exe[k] = data[:, 1:4] / 1e3, data[:, 4:7] / 1e3
            if read == 0:
                tags[0], under[0] = int(data[0, 0]), int(data[0, 7])
            tags[1] = int(data[-1, 0])
            if read <= n - 1 < read + len(data):   # the program's last sample
                under[1] = int(data[n - 1 - read, 7])
            off = np.abs(exe[k] - cmd[k]).max(axis=1) > SAMPLE_RES * 0.5
            mine = max(min(n - read, len(data)), 0)   # of these samples, the program's
            clipped += int(off[:mine].sum())
            clipped_tail += int(off[mine:].sum())
            if mine:
                here = slice(read, read + mine)
                command_error = max(command_error, _max_gap(cmd[here], rows[here]))
                tracking_error = max(tracking_error, _max_gap(exe[here], rows[here]))
            read += len(data)
    if read != total or columns != 8:
        raise HalError(f"halsampler gave {read} samples of {columns} columns, "
                       f"expected {total} of 8")
    return HalLoopResult(
        period=period, streamed=n, read=read, underruns=under[1] - under[0],
        overruns=(tags[-1] - tags[0]) - (read - 1), commanded=cmd, executed=exe,
        clipped=clipped, clipped_tail=clipped_tail, command_error=command_error,
        tracking_error=tracking_error, wall_time=wall)


def summary(r: HalLoopResult) -> str:
    """A few lines for a person: samples, underruns, executed minus commanded, clipped."""
    return "\n".join([
        f"HAL loop: {r.streamed} periods of {r.period * 1e3:g} ms streamed "
        f"({r.cycle_time:.3f} s), {r.read} samples read back in {r.wall_time:.2f} s wall",
        f"underruns within the program: {r.underruns}; sampler overruns: {r.overruns}",
        f"executed - commanded: max {r.executed_error:.2e} mm over the program "
        f"(commanded vs stream {r.command_error:.2e} mm, executed vs stream "
        f"{r.tracking_error:.2e} mm; samples hold 1e-9 mm)",
        f"samples clipped by limit3: {r.clipped} of {r.streamed} in the program, "
        f"{r.clipped_tail} of {r.read - r.streamed} after it",
    ])
