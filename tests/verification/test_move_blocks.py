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


def test_a_blocks_distances_are_dropped_with_it(boss, monkeypatch):
    """Inside shared gates the moves' exact distances live only as long as their block (a
    long stream's would grow the memo with every period): the same verdict as when the
    memo keeps them, and a memo no larger than the centres' own."""
    import contextlib

    from cadcnc.verification.gate_cache import cache_for, shared_gates
    from cadcnc.verification.material import PartFaces

    part, tp = boss
    moves = tp.points[::8]
    sizes, gates = [], []
    for keep in (False, True):
        if keep:
            monkeypatch.setattr(PartFaces, "scratch", lambda self: contextlib.nullcontext())
        with shared_gates(part):
            gates.append(gouge_gate(tp, part, moves=moves))
            sizes.append(len(cache_for(part, tp.job.tolerances).memo))
    same(*gates)
    assert sizes[0] < sizes[1]   # the moves asked for distances of their own


def test_a_streams_segments_are_joined_without_a_copy():
    """Segments that lie end to end in one array (each led by the row before) join as a
    read-only view of it; separate arrays are copied; both equal to stacking them."""
    import numpy as np

    from cadcnc.verification.program_gate import _joined

    rows = np.arange(60.0).reshape(20, 3)
    view = rows.view()
    view.flags.writeable = False
    parts = [view[0:5], view[4:12], view[11:20]]
    joined = _joined(parts)
    assert np.array_equal(joined, rows) and np.shares_memory(joined, rows)
    assert not joined.flags.writeable
    apart = [rows[0:5].copy(), rows[4:12].copy(), rows[11:20].copy()]
    copied = _joined(apart)
    assert np.array_equal(copied, rows) and not np.shares_memory(copied, rows)
    gap = _joined([view[0:5], view[6:12]])   # not adjacent: stacked
    assert np.array_equal(gap, np.vstack([rows[0:5], rows[6:12]]))
