"""The stream fuzz in the suite (issue 36): a few derandomized draws of a machine (period,
limits over decades, jerk key present or missing, mm or inch) and a feed, `cadcnc stream`
run on the block's short corner, every exit 0 judged by its positions alone: finite
differences against the INI's limits, the ends, OCCT's distance to the part
(benchmarks.reliability.fuzz_stream, which runs 500 draws: docs/reliability.md). Any
other exit is a defined code with nothing written, no traceback, no silence over 5 s."""

from __future__ import annotations

import random

import pytest

import cadcnc
from benchmarks.reliability.fuzz_stream import PROGRAMS, draw, judged, write_programs
from helpers.fixtures import FIXTURES

SEEDS = (0, 1, 2, 3, 5, 6)   # seed 4 (20 us, 47 s) left to the benchmark


@pytest.fixture(scope="module")
def setting(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz_stream")
    programs = write_programs(folder, ["corner"])
    parts = {PROGRAMS["corner"][0]: cadcnc.load_step(FIXTURES / PROGRAMS["corner"][0])}
    return programs, parts, folder


@pytest.mark.slow
@pytest.mark.parametrize("seed", SEEDS)
def test_a_stream_exits_0_only_within_the_limits_and_on_the_path(setting, seed):
    programs, parts, folder = setting
    d = draw(random.Random(seed), ["corner"])
    result = judged(d, programs, parts, folder, samples=200)
    assert result["ok"], (d, result)
