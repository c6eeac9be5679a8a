"""Two gates' results compared: the reference gate against the shared and bounded one."""

from __future__ import annotations

import pytest

DEPTH = 1e-9  # mm: the same OCCT distances, reached by other roads


def same(ref, fast) -> None:
    """Two GateResults agree: verdict, message, failing faces, cycles and moves, depths."""
    assert (ref.ok, ref.message, ref.in_material) == (fast.ok, fast.message, fast.in_material)
    assert ref.depth_mm == pytest.approx(fast.depth_mm, abs=DEPTH, nan_ok=True)
    assert [(h.face, h.n_cycles, h.cycles, h.worst_cycle) for h in ref.hits] == \
        [(h.face, h.n_cycles, h.cycles, h.worst_cycle) for h in fast.hits]
    for a, b in zip(ref.hits, fast.hits):
        assert a.depth_mm == pytest.approx(b.depth_mm, abs=DEPTH, nan_ok=True)
    if ref.sweep is None:
        assert fast.sweep is None
        return
    assert ref.sweep.proven == fast.sweep.proven
    assert ref.sweep.depth_mm == pytest.approx(fast.sweep.depth_mm, abs=DEPTH, nan_ok=True)
    assert [(h.face, h.moves, h.n_moves) for h in ref.sweep.hits] == \
        [(h.face, h.moves, h.n_moves) for h in fast.sweep.hits]
