"""Pencil: every corner of a part in one program, chained, linked, verified."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.ops.pair_program import CLIMB, climb_measure
from cadcnc.ops.pencil import pencil
from cadcnc.verification import gouge_gate
from conftest import FIXTURES, load_fixture

_programs: dict = {}


def program_of(name: str, **kw):
    key = (name, tuple(sorted(kw.items())))
    if key not in _programs:
        part = load_fixture(name) if name == "pocket" else cadcnc.load_step(
            FIXTURES / f"{name}.step")
        _programs[key] = (part, pencil(part, radius=3.0, **kw))
    return _programs[key]


def test_pocket_floor_corners_are_one_loop_without_lift():
    """The pocket's eight floor-to-wall corners (walls and wall fillets larger than the
    ball) come out as one closed loop, each cut starting where the last ended, climb."""
    part, prog = program_of("pocket")
    floor = [s for s in prog.segments if s.kind == "cut" and 17 in s.path.faces]
    assert len(floor) == 8
    k0 = next(k for k, s in enumerate(prog.segments) if s is floor[0])
    run = prog.segments[k0:k0 + 2 * len(floor) - 1]
    for a, b in zip(run, run[1:]):
        np.testing.assert_allclose(a.points[-1], b.points[0], atol=1e-3)
    lifts = [s for s in run if s.kind == "link"]
    assert all(len(s.points) == 2 and not s.rapid.any() and s.length < 1e-3 for s in lifts)
    np.testing.assert_allclose(floor[-1].points[-1], floor[0].points[0], atol=1e-3)
    assert all(climb_measure(c.path) > 0 for c in floor)
    assert prog.complete


def test_conventional_runs_the_other_way():
    _, climb = program_of("pocket")
    _, conv = program_of("pocket", side="conventional")
    floor = [c for c in conv.cuts if 17 in c.path.faces]
    assert len(floor) == 8 and all(climb_measure(c.path) < 0 for c in floor)
    assert conv.cut_length == pytest.approx(climb.cut_length, abs=1e-6)


def test_skipped_corners_carry_their_reason():
    _, prog = program_of("fillet_pocket")
    reasons = {s.reason for s in prog.skipped}
    assert "blend_rolls" in reasons            # the r 5 wall fillets: the ball rolls on them
    assert all(s.detail for s in prog.skipped)
    assert len(prog.cuts) >= 4


@pytest.mark.parametrize("name", ["pocket", "step_slot"])
def test_every_move_clears_the_part(name):
    """Every cut point touches its faces and no move, links included, cuts the part."""
    part, prog = program_of(name)
    moves = prog.all_moves()
    for cut in prog.cuts:
        gate = gouge_gate(cut.path, part, moves=moves if cut is prog.cuts[0] else None)
        assert gate.ok, gate.message
    assert len(prog.links) >= 2


def test_side_is_checked():
    with pytest.raises(cadcnc.InputError, match="side"):
        pencil(load_fixture("pocket"), radius=3.0, side="up")
