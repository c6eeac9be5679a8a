"""The baseline: a G-code program run by LinuxCNC's own planner, headless, sampled per period.

``run_ngc(ngc, machine)`` writes a simulator configuration (``linuxcnc_sim.ini``: trivkins
X Y Z, the machine's per-axis velocity and acceleration, its servo period; the display is
``linuxcncrsh``) and ``linuxcnc_sampler.hal`` (a ``sampler`` on the joint position commands
and ``motion.program-line``), starts ``linuxcnc`` (as root: in a network namespace of its
own, ``unshare --net`` with ``lo`` up, since linuxcncrsh listens on every interface),
drives it over linuxcncrsh on that namespace's 127.0.0.1
(login, estop off, machine on, auto, open, run), waits for the program to end, reads the
samples and shuts everything down. LinuxCNC 2.9's planner is trapezoidal: it has no jerk
limit, so ``machine.max_jerk`` is not used. Units: mm, s.
"""

from __future__ import annotations

import ctypes
import os
import secrets
import shutil
import socket
import string
import subprocess
import threading
import time
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ...core.work_limits import sigterm_as_interrupt
from .session import HalError, HalInterrupted, HalSession, work_folder

SAMPLE_DEPTH = 600_000  # periods the sampler FIFO holds (10 min at 1 ms)


@dataclass(frozen=True)
class BaselineRun:
    """Positions LinuxCNC commanded, one row per servo period from the start of ``run``."""

    period: float  # s
    positions: np.ndarray  # (M, 3) mm, joint position commands (X Y Z), 1e-9 mm steps
    line: np.ndarray  # (M,) motion.program-line per period
    wall_time: float  # s, from ``set run`` to the program's end
    error: str  # linuxcncrsh's ``get error`` after the run ("OK" when none)


def _axes_text(machine: Any, travel: tuple[float, float]) -> str:
    """``[AXIS_*]`` and ``[JOINT_*]`` sections with the machine's limits (mm/s, mm/s²)."""
    out = []
    for i, ax in enumerate("XYZ"):
        v, a = float(machine.max_velocity[i]), float(machine.max_acceleration[i])
        common = (f"MAX_VELOCITY = {v!r}\nMAX_ACCELERATION = {a!r}\n"
                  f"MIN_LIMIT = {travel[0]!r}\nMAX_LIMIT = {travel[1]!r}\n")
        out.append(f"[AXIS_{ax}]\n{common}")
        out.append(f"[JOINT_{i}]\nTYPE = LINEAR\nHOME = 0\n{common}FERROR = 10\n"
                   "MIN_FERROR = 10\nHOME_SEARCH_VEL = 0\nHOME_LATCH_VEL = 0\n"
                   "HOME_SEQUENCE = 0\n")
    return "\n".join(out)


def write_sim_config(machine: Any, workdir: Path, *, port: int, connectpw: str,
                     enablepw: str, travel: tuple[float, float] = (-2000.0, 2000.0)) -> Path:
    """Write the simulator's INI, sampler .hal and empty tool/parameter files; the INI path."""
    files = resources.files(__package__)
    v = np.asarray(machine.max_velocity, dtype=float)
    a = np.asarray(machine.max_acceleration, dtype=float)
    ini = string.Template(files.joinpath("linuxcnc_sim.ini").read_text()).substitute(
        port=port, connectpw=connectpw, enablepw=enablepw,
        period_ns=int(round(machine.period * 1e9)),
        # the vector limits never bind before an axis's own: the axes are the limits
        traj_v=repr(float(np.linalg.norm(v))), traj_a=repr(float(np.linalg.norm(a))),
        axes=_axes_text(machine, travel))
    hal = string.Template(files.joinpath("linuxcnc_sampler.hal").read_text()).substitute(
        depth=SAMPLE_DEPTH)
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / "linuxcnc_sampler.hal").write_text(hal)
    for name in ("sim.var", "sim.tbl"):
        (workdir / name).touch()
    path = workdir / "linuxcnc_sim.ini"
    path.write_text(ini)
    return path


CLONE_NEWNET = 0x40000000
NAMESPACED = 'ip link set lo up && exec "$@"'
"""Run inside ``unshare --net``: the new network namespace's loopback up, then LinuxCNC."""


def loopback_argv(argv: list[str]) -> tuple[list[str], bool]:
    """``argv`` run in a network namespace of its own (``unshare --net``, ``lo`` up), so
    that linuxcncrsh, which listens on every interface, is reachable from this machine
    only through that namespace; (argv, True). Without root, ``unshare`` or ``ip``:
    (argv unchanged, False)."""
    if os.geteuid() != 0 or not shutil.which("unshare") or not shutil.which("ip"):
        return argv, False
    return ["unshare", "--net", "sh", "-c", NAMESPACED, "sh", *argv], True


def _connect_in(pid: int | None, port: int, timeout: float) -> socket.socket:
    """A TCP connection to 127.0.0.1:``port`` in the network namespace of process ``pid``
    (None: this process's): made by a thread that enters the namespace (``setns``), the
    rest of the process staying where it is."""
    if pid is None:
        return socket.create_connection(("127.0.0.1", port), timeout=timeout)
    got: dict = {}

    def enter_and_connect() -> None:
        try:
            fd = os.open(f"/proc/{pid}/ns/net", os.O_RDONLY)
            try:
                libc = ctypes.CDLL(None, use_errno=True)
                if libc.setns(fd, CLONE_NEWNET) != 0:
                    err = ctypes.get_errno()
                    raise OSError(err, f"setns: {os.strerror(err)}")
            finally:
                os.close(fd)
            got["sock"] = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        except OSError as e:
            got["error"] = e

    worker = threading.Thread(target=enter_and_connect, name="cadcnc-netns")
    worker.start()
    worker.join()
    if "error" in got:
        raise got["error"]
    return got["sock"]


class Rsh:
    """A linuxcncrsh client on 127.0.0.1 (echo off, verbose on: every ``set`` is ACKed);
    ``netns_pid``: a process in the network namespace linuxcncrsh runs in (None: ours).
    ``timeout``: seconds an answer may take (LinuxCNC's task answers slowly on a loaded
    machine: ``machine on`` waits for HAL's threads)."""

    def __init__(self, port: int, connectpw: str, enablepw: str, timeout: float = 60.0,
                 netns_pid: int | None = None):
        self.timeout = timeout
        self.sock = _connect_in(netns_pid, port, timeout)
        self.buf = b""
        self.ask(f"hello {connectpw} cadcnc 1.0", expect="HELLO ACK")
        self.send(f"set enable {enablepw}")
        self.send("set echo off")
        self.ask("set verbose on", expect="SET VERBOSE ACK")

    def send(self, line: str) -> None:
        """Send one command line, without waiting for its answer."""
        self.sock.sendall(line.encode() + b"\r\n")

    def _line(self) -> str:
        while b"\n" not in self.buf:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise HalError("linuxcncrsh closed the connection")
            self.buf += chunk
        line, _, self.buf = self.buf.partition(b"\n")
        return line.decode(errors="replace").strip("\r\n ")

    def ask(self, line: str, expect: str) -> str:
        """Send a command; its answer, the first line starting with ``expect`` or a NAK.

        Lines before it (echoes of earlier commands) are skipped.
        """
        self.send(line)
        while True:
            try:
                answer = self._line()
            except TimeoutError:
                raise HalError(f"linuxcncrsh did not answer {line!r} within "
                               f"{self.timeout:g} s") from None
            if answer.startswith(expect):
                return answer
            if "NAK" in answer:
                raise HalError(f"linuxcncrsh: {line!r} answered {answer!r}")

    def close(self) -> None:
        """Close the connection."""
        try:
            self.sock.close()
        except OSError:
            pass


def _free_port() -> int:
    """A TCP port free on 127.0.0.1 at the moment of asking."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _connect(session: HalSession, port: int, cpw: str, epw: str, deadline: float,
             namespaced: bool = False) -> Rsh:
    """Wait until linuxcncrsh answers (or linuxcnc has died), then log in (in linuxcnc's
    network namespace when ``namespaced``)."""
    while True:
        if session.procs[0].poll() is not None:
            raise HalError("linuxcnc exited during start-up:\n" + _log_tail(session))
        try:
            return Rsh(port, cpw, epw, netns_pid=session.procs[0].pid if namespaced else None)
        except OSError:
            if time.monotonic() > deadline:
                raise HalError(f"linuxcncrsh not answering on port {port}:\n"
                               + _log_tail(session)) from None
            time.sleep(0.2)


def _log_tail(session: HalSession, n: int = 15) -> str:
    text = session.log.read_text(errors="replace").splitlines() if session.log.exists() else []
    return "\n".join([t for t in text if "fallback_uid" not in t][-n:])


def run_ngc(ngc: Path, machine: Any, *, workdir: Path | None = None,
            timeout: float = 300.0) -> BaselineRun:
    """Run ``ngc`` through LinuxCNC's planner with ``machine``'s limits; samples per period.

    Raises HalError with LinuxCNC's own text when it cannot start or the program fails,
    HalInterrupted on Ctrl-C; LinuxCNC and HAL are shut down in every case.
    """
    ngc = Path(ngc).resolve()
    if not ngc.is_file():
        raise HalError(f"no such G-code file: {ngc}")
    port, cpw, epw = _free_port(), secrets.token_hex(6), secrets.token_hex(6)  # <= 15 chars
    with sigterm_as_interrupt(), work_folder("lcnc") as tmp:
        work = Path(workdir) if workdir is not None else Path(tmp)
        ini = write_sim_config(machine, work, port=port, connectpw=cpw, enablepw=epw)
        session = HalSession("", work, start_timeout=60)
        rsh = None
        try:
            argv, namespaced = loopback_argv(["linuxcnc", str(ini)])
            session.start(argv=argv)
            rsh = _connect(session, port, cpw, epw, time.monotonic() + 60, namespaced)
            for cmd in ("estop off", "machine on", "mode auto", f"open {ngc}"):
                rsh.ask(f"set {cmd}", expect=f"SET {cmd.split()[0].upper()} ACK")
            session.halcmd("sets", "cadcnc-run", "TRUE")
            t0 = time.monotonic()
            rsh.ask("set run", expect="SET RUN ACK")
            while True:
                time.sleep(0.05)
                if "IDLE" in rsh.ask("get program_status", expect="PROGRAM_STATUS"):
                    break
                if time.monotonic() - t0 > timeout:
                    raise HalError(f"the program did not end within {timeout:.0f} s")
            wall = time.monotonic() - t0
            error = rsh.ask("get error", expect="ERROR").removeprefix("ERROR").strip()
            session.halcmd("sets", "cadcnc-run", "FALSE")
            depth = int(session.get("sampler.0.curr-depth"))
            data = _read_samples(session, work, depth)
            try:
                rsh.send("shutdown")
            except OSError:
                pass
            _wait_exit(session.procs[0], 20)
        except KeyboardInterrupt:
            session.stop()
            raise HalInterrupted("LinuxCNC run interrupted (Ctrl-C or SIGTERM); LinuxCNC and HAL "
                                 "shut down") from None
        finally:
            if rsh is not None:
                rsh.close()
            problems = session.stop()
        if problems:
            raise HalError("LinuxCNC stopped uncleanly: " + "; ".join(problems))
    return BaselineRun(period=machine.period, positions=data[:, :3] / 1e3,
                       line=data[:, 3].astype(np.int64), wall_time=wall, error=error)


def _read_samples(session: HalSession, work: Path, depth: int) -> np.ndarray:
    """``depth`` samples from the sampler FIFO as an (M, 4) array."""
    if depth <= 0:
        raise HalError("the sampler recorded nothing: did the program run?")
    if depth >= SAMPLE_DEPTH - 1:
        raise HalError(f"the sampler FIFO filled up ({SAMPLE_DEPTH} periods): program too long")
    out_path = work / "baseline_samples.txt"
    with open(out_path, "wb") as out:
        proc = session.spawn(["halsampler", "-c", "0", "-n", str(depth)], stdout=out,
                             stderr=subprocess.DEVNULL)
    _wait_exit(proc, 60)
    data = np.loadtxt(out_path, ndmin=2)
    if data.shape != (depth, 4):
        raise HalError(f"halsampler gave {data.shape}, expected ({depth}, 4)")
    return data


def _wait_exit(proc: subprocess.Popen, seconds: float) -> None:
    """Wait for a process to end, at most ``seconds`` (teardown handles the rest)."""
    try:
        proc.wait(timeout=seconds)
    except subprocess.TimeoutExpired:
        pass
