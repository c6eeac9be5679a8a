"""A set of output files written all or nothing, checked before anything is computed.

A machinist runs ``cadcnc path ... && send-to-machine``: a failed or interrupted run must
leave no half file and never destroy an earlier good one. :class:`OutputSet` checks every
destination up front (known suffix, existing writable folder, not a folder itself, not one
of the run's input files (exit 2), a name the file system accepts), then writes the whole set to
temporary files beside their destinations and renames them only when all are ready, with
Ctrl-C (SIGINT) deferred during the renames. A symlink destination is followed: its target
is replaced, the link stays.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from ..core.errors import OutputError, OutputIsInputError
from ..core.interrupts import signals_deferred
from ..core.work_limits import sigterm_as_interrupt
from .atomic import NAME_MAX, temp_prefix

TEXT_SLICE = 1 << 24
"""Characters of a text output encoded at a time while it is written."""


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def check_destination(out, suffixes: tuple[str, ...], inputs=()) -> Path:
    """The real path ``out`` will be written to (symlinks followed), or OutputError."""
    out = Path(out)
    suffix = out.suffix.lower()
    if suffix not in suffixes:
        kind = "picture" if set(suffixes) <= {".png", ".glb"} else "output"
        raise OutputError(f"{out}: unknown {kind} format {suffix or '(no suffix)'!r}; use "
                          f"{' or '.join(suffixes) if len(suffixes) == 2 else 'one of ' + ', '.join(suffixes)}")
    if len(os.fsencode(out.name)) > NAME_MAX:
        raise OutputError(f"{str(out)[:40]}...: file name too long ({len(out.name)} "
                          f"characters; at most {NAME_MAX} bytes)")
    target = Path(os.path.realpath(out))
    folder = target.parent
    if not folder.is_dir():
        if out.is_symlink():
            raise OutputError(f"{out}: a symbolic link to {os.readlink(out)}, whose folder "
                              f"{folder} does not exist")
        raise OutputError(f"{out}: cannot write, folder {out.parent} does not exist")
    if target.is_dir():
        raise OutputError(f"{out}: is a folder")
    if not os.access(folder, os.W_OK):
        raise OutputError(f"{out}: cannot write, folder {out.parent} is not writable")
    check_not_inputs([out], inputs)
    return target


def check_not_inputs(destinations, inputs) -> None:
    """OutputIsInputError (exit 2) naming both when a destination is one of ``inputs``
    (a path, or None), symbolic links and ``..`` resolved; a destination's folder need
    not exist yet."""
    sources = [Path(s) for s in inputs if s is not None and Path(s).exists()]
    for out in destinations:
        out = Path(out)
        target = Path(os.path.realpath(out))
        for source in sources:
            if _same_file(target, source) if target.exists() else \
                    target == Path(os.path.realpath(source)):
                raise OutputIsInputError(f"{out}: is an input of this run ({source}); "
                                         "refusing to write over it")


class OutputSet:
    """Destinations checked now, written later all at once (see the module doc)."""

    def __init__(self, destinations, suffixes: tuple[str, ...], inputs=()):
        self.destinations = [Path(d) for d in destinations]
        self.targets = {}
        for d in self.destinations:
            target = check_destination(d, suffixes, inputs)
            if target in self.targets.values():
                raise OutputError(f"{d}: named twice among the outputs")
            self.targets[d] = target

    def write(self, contents: dict) -> None:
        """Write ``{destination: bytes or str, or an iterable of them}`` (every destination
        of the set) atomically; an iterable is written a chunk at a time as it yields them
        (an error it raises leaves nothing written)."""
        contents = {Path(k): v for k, v in contents.items()}
        missing = [str(d) for d in self.destinations if d not in contents]
        if missing:
            raise OutputError(f"no content for {', '.join(missing)}")
        temps: list[tuple[str, Path, Path]] = []
        try:
            with sigterm_as_interrupt():   # SIGTERM, too, leaves no temporary file
                self._write_temps(contents, temps)
                with signals_deferred():
                    for tmp, target, _ in temps:
                        os.replace(tmp, target)
        except OSError as e:
            name = temps[-1][2] if temps else self.destinations[0]
            raise OutputError(f"{name}: cannot write ({e.strerror or e})") from e
        finally:
            for tmp, _, _ in temps:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)

    def _write_temps(self, contents: dict, temps: list) -> None:
        """Every destination's bytes to a temporary file beside it (listed in ``temps``)."""
        for d in self.destinations:
            target = self.targets[d]
            data = contents[d]
            fd, tmp = tempfile.mkstemp(prefix=temp_prefix(target), suffix=".tmp",
                                       dir=target.parent)
            temps.append((tmp, target, d))
            with os.fdopen(fd, "wb") as fh:
                chunks = (data,) if isinstance(data, (str, bytes, bytearray)) else data
                for chunk in chunks:
                    if isinstance(chunk, str):   # encoded a slice at a time: no second copy
                        for a in range(0, len(chunk), TEXT_SLICE):
                            fh.write(chunk[a:a + TEXT_SLICE].encode("utf-8"))
                    else:
                        fh.write(chunk)
            os.chmod(tmp, 0o666 & ~_umask())


def write_one(out, data, suffixes: tuple[str, ...], inputs=()) -> None:
    """One file, checked and written atomically."""
    OutputSet([out], suffixes, inputs).write({Path(out): data})
