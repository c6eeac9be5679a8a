"""The program of a pair: every stretch cut, limits reached, links, selection, refusals."""

from __future__ import annotations

import json

import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import EXIT_NOTHING, InputError, NothingToCutError
from cadcnc.core.job import Job, PairPath, Tool
from cadcnc.ops.path.pair_program import LIMIT_SLACK, program_for_job, safe_height
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "stretch_fixtures.json").read_text())
_parts: dict = {}


def part_of(name: str):
    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIXTURES / FACTS[name]["file"])
    return _parts[name]


def job_for(name: str, **op) -> Job:
    f = FACTS[name]
    return Job(Tool(f["radius"], shank_length=f["shank"]), 1500.0, 0.004,
               PairPath(faces=tuple(f["pair"]), edge=op.pop("edge", None), **op))


@pytest.fixture(scope="module")
def shelf():
    return program_for_job(part_of("shelf"), job_for("shelf"))


def test_every_stretch_is_cut_to_its_limits(shelf):
    """The shelf's corner has two stretches (the shank hits the shelf in between): two
    cuts, each from limit to limit (closed forms in the sidecar), one link between."""
    want = FACTS["shelf"]["stretches"]
    assert [s.kind for s in shelf.segments] == ["link", "cut", "link", "cut", "link"]
    for cut, st in zip(shelf.cuts, want):
        assert cut.at_limit and cut.complete
        # the limits are where the clearance reaches R' - tol: within the slack of the
        # closed form, and inside the stretch (never beyond it)
        for point, limit in ((cut.points[0], st["start"]["p"]), (cut.points[-1], st["end"]["p"])):
            assert np.linalg.norm(point - limit) <= LIMIT_SLACK
        assert cut.edge == 1 and cut.path.job.operation.stretch == cut.stretch
    assert [c.stretch for c in shelf.cuts] == [1, 2]
    assert shelf.complete and not shelf.skipped
    link = shelf.segments[2]
    assert link.points[:, 2].max() == pytest.approx(safe_height(part_of("shelf"),
                                                                 shelf.job))


def test_stretch_selection():
    one = program_for_job(part_of("shelf"), job_for("shelf", stretch=2))
    assert len(one.cuts) == 1 and one.cuts[0].stretch == 2
    np.testing.assert_allclose(one.cuts[0].points[-1], FACTS["shelf"]["stretches"][1]["end"]["p"],
                               atol=LIMIT_SLACK)
    with pytest.raises(InputError, match="no stretch 3"):
        program_for_job(part_of("shelf"), job_for("shelf", stretch=3))
    with pytest.raises(InputError, match="no edge 2"):
        program_for_job(part_of("shelf"), job_for("shelf", edge=1))


@pytest.mark.parametrize("name, words", [
    ("slot", ["no feasible ball position", "third face", "face 5"]),
    ("undercut", ["no feasible ball position", "shank touches face 4"]),
])
def test_no_stretch_is_refused_with_the_reason(name, words):
    with pytest.raises(NothingToCutError) as err:   # valid input, nothing to cut: exit 3
        program_for_job(part_of(name), job_for(name))
    assert err.value.exit_code == EXIT_NOTHING
    for w in words:
        assert w in str(err.value)


def test_a_start_outside_every_stretch_moves_to_the_nearest_limit():
    """A start under the shelf (x = 30, where the shank hits it) moves to a stretch
    limit (22 or 38 along x), and the program says so."""
    start = (30.0, 8.0, 11.0)
    prog = program_for_job(part_of("shelf"), job_for("shelf", start=start))
    assert prog.notes and "moved to the nearest stretch limit" in prog.notes[0]
    first = prog.cuts[0].points[0]
    assert min(abs(first[0] - 22.0), abs(first[0] - 38.0)) <= LIMIT_SLACK


def test_boss_on_a_curved_floor_two_stretches():
    """Contacts leave the boss over its top: two mirror stretches, each cut limit to limit."""
    prog = program_for_job(part_of("boss"), job_for("boss"))
    assert len(prog.cuts) == 2 and prog.complete
    for cut, st in zip(prog.cuts, FACTS["boss"]["stretches"]):
        assert np.linalg.norm(cut.points[0] - st["start"]["p"]) <= 0.02
        assert np.linalg.norm(cut.points[-1] - st["end"]["p"]) <= 0.02
