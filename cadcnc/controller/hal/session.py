"""One HAL session in subprocesses: environment, a machine-wide lock, start, pins, teardown.

HAL is one set of shared memory per machine, so cadcnc runs one session at a time (a file
lock) and refuses to start beside a HAL it did not start. As root, ``rtapi_app`` runs only
with ``RTAPI_UID`` naming a non-root uid and ``RTAPI_FIFO_PATH`` (a socket file) in a
world-writable directory; it then uses POSIX non-realtime threads. ``halrun -I -f FILE``
unloads everything when its standard input closes, so the session keeps it open and the
HAL goes away even if this process is killed. Teardown always runs ``halrun -U``.
"""

from __future__ import annotations

import fcntl
import os
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from ...core.errors import EXIT_INTERNAL, EXIT_INTERRUPTED, CadcncError

LOCK_PATH = Path(tempfile.gettempdir()) / "cadcnc-hal.lock"
NOBODY_UID = 65534
FOLDER = re.compile(r"^cadcnc-(hal|lcnc)-(\d+)-")
"""A run's temporary folder: ``cadcnc-hal-PID-XXXX`` (HAL loop) or ``cadcnc-lcnc-PID-XXXX``
(LinuxCNC baseline), PID the process that made it."""


def work_folder(kind: str) -> tempfile.TemporaryDirectory:
    """A temporary folder for one run, named by ``kind`` ("hal", "lcnc") and this
    process's id; stale folders of dead runs are removed first (:func:`remove_stale`)."""
    remove_stale()
    return tempfile.TemporaryDirectory(prefix=f"cadcnc-{kind}-{os.getpid()}-")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale(root=None) -> list[Path]:
    """Remove the temporary folders of cadcnc runs whose process is gone (killed by
    SIGKILL, which leaves no time to clean up); a live process's folder is never touched,
    nor a folder without a process id in its name. Returns what was removed."""
    root = Path(tempfile.gettempdir() if root is None else root)
    removed = []
    try:
        entries = list(root.iterdir())
    except OSError:
        return removed
    for entry in entries:
        found = FOLDER.match(entry.name)
        if found is None or int(found.group(2)) == os.getpid() or _alive(int(found.group(2))):
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry, ignore_errors=True)
            removed.append(entry)
    return removed


class HalError(CadcncError):
    """HAL could not start, run or stop (the message holds the tool's own error text): an
    error of the machine's controller tools, not of the input."""

    exit_code = EXIT_INTERNAL


class HalInterrupted(HalError):
    """Ctrl-C during a HAL run; HAL was unloaded before this was raised."""

    exit_code = EXIT_INTERRUPTED


def hal_available() -> str | None:
    """None when halrun, halcmd, halstreamer and halsampler are on PATH, else what is missing."""
    missing = [t for t in ("halrun", "halcmd", "halstreamer", "halsampler") if not shutil.which(t)]
    return None if not missing else "not on PATH: " + ", ".join(missing)


def rtapi_pids() -> list[int]:
    """Process ids of every running ``rtapi_app`` (zombies excluded)."""
    pids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        name, state = stat[stat.find("(") + 1:stat.rfind(")")], stat[stat.rfind(")") + 2:][:1]
        if name == "rtapi_app" and state != "Z":
            pids.append(int(entry.name))
    return pids


def _tail(path: Path, lines: int = 12) -> str:
    """The last lines of a log, without rtapi's per-call uid notice."""
    try:
        text = path.read_text(errors="replace").splitlines()
    except OSError:
        return ""
    kept = [t for t in text if "fallback_uid" not in t and t.strip()]
    return "\n".join(kept[-lines:])


def _file_error(log: Path, name: str) -> str | None:
    """The first ``NAME:LINE: message`` halcmd printed for the .hal file, if any."""
    try:
        text = log.read_text(errors="replace")
    except OSError:
        return None
    found = re.search(rf"^\S*{re.escape(name)}:\d+: .*$", text, re.MULTILINE)
    return found.group(0) if found else None


class HalSession:
    """A HAL started from a .hal file (or by ``linuxcnc``); a context manager whose
    teardown always runs."""

    def __init__(self, hal_text: str, workdir: Path, *, lock_timeout: float = 120.0,
                 start_timeout: float = 30.0):
        self.hal_text = hal_text
        self.workdir = Path(workdir)
        self.lock_timeout = lock_timeout
        self.start_timeout = start_timeout
        self.env = dict(os.environ)
        self.procs: list[subprocess.Popen] = []
        self._halrun: subprocess.Popen | None = None
        self._lock_fd: int | None = None
        self.log = self.workdir / "halrun.log"

    # -- environment ---------------------------------------------------------------
    def _prepare(self) -> None:
        """Working folder, a world-writable folder for rtapi's socket, the environment."""
        self.workdir.mkdir(parents=True, exist_ok=True)
        os.chmod(self.workdir, 0o755)
        fifo_dir = self.workdir / "rtapi"
        fifo_dir.mkdir(exist_ok=True)
        os.chmod(fifo_dir, 0o1777)
        self.env["RTAPI_FIFO_PATH"] = str(fifo_dir / "rtapi_fifo")
        if os.geteuid() == 0:
            self.env["RTAPI_UID"] = str(NOBODY_UID)

    def _lock(self) -> None:
        """Take the machine-wide cadcnc HAL lock, waiting up to ``lock_timeout`` s."""
        fd = os.open(LOCK_PATH, os.O_RDWR | os.O_CREAT, 0o666)
        deadline = time.monotonic() + self.lock_timeout
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    os.close(fd)
                    raise HalError(f"another cadcnc HAL run holds {LOCK_PATH} "
                                   f"(waited {self.lock_timeout:.0f} s)") from None
                time.sleep(0.1)
        self._lock_fd = fd

    # -- commands ------------------------------------------------------------------
    def halcmd(self, *args: str, timeout: float = 20.0) -> str:
        """Run one ``halcmd`` command against this session; its stdout, or HalError."""
        try:
            out = subprocess.run(["halcmd", *args], env=self.env, capture_output=True,
                                 text=True, timeout=timeout, stdin=subprocess.DEVNULL)
        except subprocess.TimeoutExpired:
            raise HalError(f"halcmd {' '.join(args)}: no answer in {timeout:.0f} s") from None
        if out.returncode != 0:
            err = "\n".join(t for t in out.stderr.splitlines() if "fallback_uid" not in t)
            raise HalError(f"halcmd {' '.join(args)} failed: {err.strip()}")
        return out.stdout

    def get(self, name: str, kind: str = "p") -> str:
        """The value of a pin (``kind='p'``) or signal (``'s'``), as halcmd prints it."""
        return self.halcmd(f"get{kind}", name).strip()

    def spawn(self, argv: list[str], **kw) -> subprocess.Popen:
        """Start a helper (halstreamer, halsampler, linuxcnc) owned by this session."""
        proc = subprocess.Popen(argv, env=kw.pop("env", self.env), start_new_session=True,
                                **kw)
        self.procs.append(proc)
        return proc

    # -- life cycle ----------------------------------------------------------------
    def start(self, ready_signal: str = "cadcnc-ready", argv: list[str] | None = None) -> None:
        """Lock, check no HAL runs, start HAL, wait for ``ready_signal`` to be TRUE.

        HAL starts as ``halrun -I -f`` on :attr:`hal_text`, or as ``argv`` (``linuxcnc
        FILE.ini``, whose own .hal files set ``ready_signal``).
        """
        self._prepare()
        self._lock()
        others = rtapi_pids()
        if others:
            raise HalError(f"a HAL is already running (rtapi_app pid {others}); cadcnc does "
                           "not share it: stop it first (halrun -U)")
        hal_file = self.workdir / "cadcnc.hal"
        if argv is None:
            hal_file.write_text(self.hal_text)
            argv = ["halrun", "-I", "-f", str(hal_file)]
        with open(self.log, "wb") as log:
            self._halrun = self.spawn(argv, stdin=subprocess.PIPE, stdout=log, stderr=log,
                                      cwd=self.workdir)
        deadline = time.monotonic() + self.start_timeout
        while True:
            if self._halrun.poll() is not None:
                raise HalError(f"HAL did not start ({argv[0]} exit {self._halrun.returncode}):\n"
                               + _tail(self.log))
            failed = _file_error(self.log, hal_file.name)
            if failed:  # halrun -I stays at its prompt after an error in the file
                raise HalError(f"HAL did not start: {failed}\n" + _tail(self.log))
            try:
                if self.get(ready_signal, "s").upper() == "TRUE":
                    return
            except HalError:
                pass
            if time.monotonic() > deadline:
                raise HalError(f"HAL not ready after {self.start_timeout:.0f} s:\n"
                               + _tail(self.log))
            time.sleep(0.2)

    def stop(self) -> list[str]:
        """Stop helpers, close halrun's stdin, ``halrun -U``; returns problems (never raises).

        A Ctrl-C or SIGTERM during teardown is ignored: the teardown is what the user asked for.
        """
        main = threading.current_thread() is threading.main_thread()
        signals = (signal.SIGINT, signal.SIGTERM) if main else ()
        previous = [signal.signal(sig, signal.SIG_IGN) for sig in signals]
        try:
            return self._stop()
        finally:
            for sig, handler in zip(signals, previous):
                signal.signal(sig, handler)

    def _stop(self) -> list[str]:
        """The teardown itself (see :meth:`stop`)."""
        problems: list[str] = []
        for proc in reversed(self.procs):
            if proc is self._halrun or proc.poll() is not None:
                continue
            _end(proc)
        if self._halrun is not None and self._halrun.poll() is None:
            try:
                self._halrun.stdin.close()
                self._halrun.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                _end(self._halrun)
        if self._halrun is not None:  # only a HAL this session started is unloaded
            try:
                subprocess.run(["halrun", "-U"], env=self.env, capture_output=True,
                               timeout=30, stdin=subprocess.DEVNULL)
            except (OSError, subprocess.TimeoutExpired) as e:
                problems.append(f"halrun -U: {e}")
        left = rtapi_pids() if self._halrun is not None else []
        for pid in left:  # only reached when halrun -U failed: ours, since we hold the lock
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        if left:
            problems.append(f"rtapi_app {left} killed after halrun -U")
        self._halrun = None
        if self._lock_fd is not None:
            os.close(self._lock_fd)
            self._lock_fd = None
        return problems

    def __enter__(self) -> "HalSession":
        try:
            self.start()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


def _end(proc: subprocess.Popen) -> None:
    """Terminate a helper's process group, then kill it if it lingers."""
    for sig, wait in ((signal.SIGTERM, 3), (signal.SIGKILL, 3)):
        try:
            os.killpg(proc.pid, sig)
        except OSError:
            return
        try:
            proc.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue
