"""A long polyline of moves (a stream's periods) is gated in blocks
(``whole_part.MOVES_BLOCK``) so that the check's arrays stay bounded: the verdict, the
depths and every failing face's moves are those of the whole polyline checked at once."""

from __future__ import annotations

import pytest

from cadcnc.verification import gouge_gate, whole_part
from helpers.fixtures import fixture_path, load_fixture
from helpers.gate_results import same


@pytest.fixture(scope="module")
def boss():
    return load_fixture("bspline_boss"), fixture_path("bspline_boss", 4, 5, radius=3.0)


@pytest.mark.parametrize("every", [1, 8])   # the cut's own points; 0.8 mm chords that sag
def test_moves_in_blocks_are_judged_as_all_at_once(boss, monkeypatch, every):
    part, tp = boss
    moves = tp.points[::every]
    whole = gouge_gate(tp, part, moves=moves)
    monkeypatch.setattr(whole_part, "MOVES_BLOCK", 7)   # many blocks, failing runs across
    blocks = gouge_gate(tp, part, moves=moves)
    same(whole, blocks)
    assert blocks.sweep.n_moves == whole.sweep.n_moves == len(moves) - 1
    assert blocks.sweep.worst_move == whole.sweep.worst_move
    if every == 8:   # the reproduction fails on face 5 over runs longer than a block
        assert not blocks.ok and any(b - a >= 7 for h in blocks.sweep.hits
                                     for a, b in h.moves)
    else:
        assert blocks.ok and blocks.sweep.depth_bound_mm <= blocks.limit_mm
