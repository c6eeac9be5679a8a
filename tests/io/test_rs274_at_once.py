"""rs274 keeps its tool table in $HOME/.tool.mmap and truncates it on every start, so runs
at once (a command's worker threads, two commands, a test suite on two cores) read each
other's half-written table and stop before M2 (2 of 60 runs four at a time, 2026-11-30).
``canonical_calls`` gives each run a home of its own: 80 runs four at a time all read the
program to its end."""

from __future__ import annotations

import shutil
from concurrent.futures import ThreadPoolExecutor

import pytest

from cadcnc.core.errors import InputError
from cadcnc.io.gcode_reader import canonical_calls

PROGRAM = "G21 G90 G17\nG0 Z10\nG0 X0 Y0\nG1 Z0 F300\nG1 X10 F1500\nG2 X20 Y0 I5 J0\nG0 Z10\nM2\n"


@pytest.mark.skipif(shutil.which("rs274") is None, reason="LinuxCNC rs274 not installed")
def test_runs_at_once_each_read_the_whole_program(tmp_path):
    ngc = tmp_path / "p.ngc"
    ngc.write_text(PROGRAM)

    def ends(_):
        try:
            return "PROGRAM_END" in [name for name, _ in canonical_calls(ngc, strict=True)]
        except InputError:   # "rs274 could not read the program (no M2)"
            return False

    with ThreadPoolExecutor(4) as pool:
        assert all(pool.map(ends, range(80)))
