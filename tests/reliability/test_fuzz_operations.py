"""Property-based fuzz of the operations (issue 20): `pencil` and `finish` through the CLI.

Hypothesis draws an operation on a fixture, a ball radius (1e-3 to 1e3 mm, log-uniform),
a stepover, the gouge limit and chord tolerance (within their bounds), and a clearance.
Every exit 0 is judged independently on the G-code as written: OCCT's distance from each
move's samples to the part's faces and OCCT's solid classifier give the ball's depth
(cadcnc.testing.moves_judge); none may be deeper than the gouge limit. Every exit 5 is
judged by the same judge, which must find such a depth (the refusal is backed). Every
other exit is one of the defined codes, and nothing is written then. Examples are
derandomized, so a failure reproduces; `python -m benchmarks.reliability.fuzz_operations`
runs it longer (its result is in docs/reliability.md).
"""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import cadcnc
from benchmarks.reliability.fuzz_operations import CASES, judged, trial_args
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

pytestmark = pytest.mark.slow  # over about 5 s a test (pyproject.toml)

EXAMPLES = 6
"""Draws in the suite (about 15 s); benchmarks.reliability.fuzz_operations runs more."""
OUTCOMES: list = []
_parts: dict = {}


def part_of(name: str):
    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIXTURES / name)
    return _parts[name]


@settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
          phases=(Phase.explicit, Phase.generate),
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(case=st.sampled_from(CASES[:2] * 3 + CASES[2:]), log_r=st.floats(-3.0, 3.0),
       stepover=st.floats(6.0, 12.0), gouge=st.sampled_from(["0.0005", "0.001", "0.1"]),
       chord=st.sampled_from([None, "0.0005", "0.002"]), lift=st.floats(-2.0, 30.0))
def test_an_operation_exits_0_only_when_an_independent_judge_agrees(
        tmp_path_factory, case, log_r, stepover, gouge, chord, lift):
    part = part_of(case[1])
    radius = 10.0 ** log_r
    out = tmp_path_factory.mktemp("fuzz") / "p.ngc"
    args = trial_args(case, radius, stepover, gouge, chord, part.top, lift, out)
    result = judged(args, part, radius, gouge, run=lambda *a: _run(*a))
    OUTCOMES.append((case[0], case[1], radius, result["exit"]))
    assert result["ok"], result


def _run(*args) -> tuple[int, str]:
    run = cadcnc_cli(*args)
    return run.returncode, run.stderr


def test_the_operation_fuzz_exercises_real_programs():
    """Run after the fuzz above: at least 40 % of its draws wrote a program (exit 0)."""
    if not OUTCOMES:
        pytest.skip("run with the fuzz")
    ok = sum(code == 0 for *_, code in OUTCOMES)
    assert ok >= 0.4 * len(OUTCOMES), OUTCOMES
