"""Read a STEP file into an OCCT shape: clear errors, and OCCT's own chatter captured.

OCCT's STEP reader prints warnings (``*** ERR StepReaderData : Unresolved Reference
***``) straight to the process's standard output, which would corrupt machine-readable
output such as ``cadcnc faces --json``. The reader runs with file descriptor 1 redirected
to a temporary file; what it printed is returned as warnings for the caller to report.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import re
import shutil
import sys
import tempfile

from OCP.IFSelect import IFSelect_RetDone
from OCP.Message import Message, Message_Gravity
from OCP.STEPControl import STEPControl_Reader
from OCP.TopoDS import TopoDS_Shape

from ..core.errors import StepFileError

_LIBC = ctypes.CDLL(None)
HEADER = b"ISO-10303-21"
BOM = b"\xef\xbb\xbf"
ANSI_ESCAPE = re.compile(r"\x1b\[[0-9;]*m")  # OCCT colours its messages
HEADER_SEARCH_BYTES = 65536  # a leading comment or byte-order mark may precede the header


@contextlib.contextmanager
def native_stdout_captured(lines: list[str]):
    """Redirect file descriptor 1 while the block runs; append what was printed to ``lines``."""
    sys.stdout.flush()
    saved = os.dup(1)
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 1)
        try:
            yield
        finally:
            _LIBC.fflush(None)  # C stdio buffers what OCCT wrote (std::cout) when not a tty
            os.dup2(saved, 1)
            os.close(saved)
            tmp.seek(0)
            text = tmp.read().decode("utf-8", "replace")
            text = ANSI_ESCAPE.sub("", text)
            lines += [ln.strip() for ln in text.splitlines() if ln.strip()]


@contextlib.contextmanager
def occt_messages_from(level):
    """OCCT's printers report messages of ``level`` and above while the block runs (CadQuery
    raises the level to failures only when imported; the reader's warnings are wanted)."""
    printers = list(Message.DefaultMessenger_s().Printers())
    saved = [pr.GetTraceLevel() for pr in printers]
    for pr in printers:
        pr.SetTraceLevel(level)
    try:
        yield
    finally:
        for pr, old in zip(printers, saved):
            pr.SetTraceLevel(old)


def check_step_file(path: str) -> bool:
    """StepFileError unless ``path`` is a readable file with an ISO-10303-21 header; True
    when the file starts with a UTF-8 byte-order mark (which OCCT's reader refuses)."""
    if not os.path.exists(path):
        raise StepFileError(f"{path}: no such file")
    if os.path.isdir(path):
        raise StepFileError(f"{path}: is a directory, not a STEP file")
    try:
        with open(path, "rb") as fh:
            head = fh.read(HEADER_SEARCH_BYTES)
    except OSError as e:
        raise StepFileError(f"{path}: cannot read ({e.strerror or e})") from None
    if HEADER not in head:
        raise StepFileError(f"{path}: not a STEP file (no ISO-10303-21 header)")
    return head.startswith(BOM)


def read_step(path: str) -> tuple[TopoDS_Shape, list[str]]:
    """(shape, warnings OCCT printed while reading) of a STEP file, in mm."""
    if check_step_file(path):
        with tempfile.TemporaryDirectory() as tmp:  # the same bytes without the mark
            copy = os.path.join(tmp, os.path.basename(path))
            with open(path, "rb") as src, open(copy, "wb") as dst:
                src.read(len(BOM))
                shutil.copyfileobj(src, dst)
            return _read(copy, path)
    return _read(path, path)


def _read(file: str, name: str) -> tuple[TopoDS_Shape, list[str]]:
    warnings: list[str] = []
    reader = STEPControl_Reader()
    with native_stdout_captured(warnings), occt_messages_from(Message_Gravity.Message_Info):
        status = reader.ReadFile(file)
        if status == IFSelect_RetDone:
            reader.TransferRoots()
    if status != IFSelect_RetDone:
        raise StepFileError(f"{name}: STEP file could not be read (syntax or schema error)")
    return reader.OneShape(), warnings
