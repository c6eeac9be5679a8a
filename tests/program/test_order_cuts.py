"""order_cuts (vectorized) gives exactly the order of the straightforward loops it replaced.

The loops are kept here as the specification: chains by the nearest start within ``join``
(argsort order), nearest neighbour (the first of equals), then first-improvement 2-opt
comparing ``after + inner_after < before + inner_before - 1e-9`` with the sums added left
to right. Instances include ties: duplicate points, points on a grid (equal distances),
and cuts that chain within ``join``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

import cadcnc
from cadcnc.core.job import Job, Pencil, Tool
from cadcnc.ops.pencil import pencil_program
from cadcnc.program.linking import TWO_OPT_MAX, order_cuts
from helpers.fixtures import FIXTURES


@dataclass
class Item:
    """What order_cuts reads of a cut: its points (N, 3) mm."""

    points: np.ndarray


def travel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.hypot(*(b[:2] - a[:2])))


def order_by_loops(cuts: list, join: float = 0.0) -> list:
    """The specification: order_cuts as the Python loops it replaced computed it."""
    if len(cuts) < 2:
        return list(cuts)
    starts = np.array([c.points[0] for c in cuts])
    ends = np.array([c.points[-1] for c in cuts])
    follower: dict[int, int] = {}   # i's end meets follower[i]'s start
    for i in range(len(cuts)):
        d = np.linalg.norm(starts - ends[i], axis=1)
        d[i] = np.inf
        near = [int(j) for j in np.argsort(d) if d[j] <= join]   # sorted: a prefix
        free = [j for j in near if j not in follower.values()]
        if free:
            follower[i] = free[0]
    heads = [i for i in range(len(cuts)) if i not in follower.values()] or [0]
    chains, seen = [], set()
    for h in heads + list(range(len(cuts))):
        chain, k = [], h
        while k is not None and k not in seen:
            chain.append(k)
            seen.add(k)
            k = follower.get(k)
        if chain:
            chains.append(chain)

    def first(ch):
        return starts[ch[0]]

    def last(ch):
        return ends[ch[-1]]

    order = [chains.pop(0)]
    while chains:
        k = min(range(len(chains)), key=lambda m: travel(last(order[-1]), first(chains[m])))
        order.append(chains.pop(k))
    improved = len(order) <= TWO_OPT_MAX
    while improved:
        improved = False
        for i in range(1, len(order) - 1):
            for j in range(i + 1, len(order)):
                before = travel(last(order[i - 1]), first(order[i]))
                after = travel(last(order[i - 1]), first(order[j]))
                if j + 1 < len(order):
                    before += travel(last(order[j]), first(order[j + 1]))
                    after += travel(last(order[i]), first(order[j + 1]))
                inner_before = sum(travel(last(order[m]), first(order[m + 1]))
                                   for m in range(i, j))
                inner_after = sum(travel(last(order[m + 1]), first(order[m]))
                                  for m in range(i, j))
                if after + inner_after < before + inner_before - 1e-9:
                    order[i:j + 1] = order[i:j + 1][::-1]
                    improved = True
    return [cuts[k] for chain in order for k in chain]


def same(got: list, want: list) -> bool:
    return len(got) == len(want) and all(g is w for g, w in zip(got, want))


def instance(rng: np.random.Generator, n: int, kind: str) -> tuple[list, float]:
    """n cuts (start, middle, end) and a join distance, of one kind of tie."""
    if kind == "grid":      # integer points: many equal distances, some duplicates
        ends = rng.integers(0, 4, size=(n, 2, 3)).astype(float)
    elif kind == "dups":    # few distinct points, each used many times
        pool = rng.uniform(-10, 10, size=(max(2, n // 4), 3))
        ends = pool[rng.integers(0, len(pool), size=(n, 2))]
    elif kind == "chains":  # many cuts start within join of another's end
        ends = rng.uniform(-20, 20, size=(n, 2, 3))
        for k in range(1, n):
            if rng.random() < 0.6:
                ends[k, 0] = ends[rng.integers(0, k), 1] + rng.uniform(-4e-4, 4e-4, 3)
    else:                   # distinct random points
        ends = rng.uniform(-50, 50, size=(n, 2, 3))
    cuts = [Item(np.array([s, 0.5 * (s + e), e])) for s, e in ends]
    join = 1e-3 if kind == "chains" else float(rng.choice([0.0, 1e-3, 1.0]))
    return cuts, join


@pytest.mark.parametrize("kind", ["random", "grid", "dups", "chains"])
def test_the_same_order_as_the_loops_on_random_instances(kind):
    rng = np.random.default_rng(["random", "grid", "dups", "chains"].index(kind))
    for n in [0, 1, 2, 3, 4, 5, 6, 7, 9, 12, 16, 24] * 4 + [40]:
        cuts, join = instance(rng, n, kind)
        assert same(order_cuts(cuts, join), order_by_loops(cuts, join)), (kind, n, join)


def test_the_same_order_above_the_two_opt_limit():
    """More chains than TWO_OPT_MAX: chains and nearest neighbour only."""
    rng = np.random.default_rng(7)
    cuts, _ = instance(rng, TWO_OPT_MAX + 20, "random")
    got = order_cuts(cuts, 0.0)
    assert same(got, order_by_loops(cuts, 0.0))
    assert sorted(map(id, got)) == sorted(map(id, cuts))


def test_the_order_is_a_permutation_that_keeps_chains_and_shortens_travel():
    rng = np.random.default_rng(11)
    cuts, join = instance(rng, 30, "chains")
    got = order_cuts(cuts, join)
    assert sorted(map(id, got)) == sorted(map(id, cuts))
    chained = sum(np.linalg.norm(b.points[0] - a.points[-1]) <= join
                  for a, b in zip(got, got[1:]))
    assert chained > 5

    def length(seq):
        return sum(travel(a.points[-1], b.points[0]) for a, b in zip(seq, seq[1:]))
    assert length(got) < length(cuts)


def test_the_same_order_on_a_real_pencil_program(monkeypatch):
    """The cuts pencil orders on step_slot: the new order is the loops' order."""
    seen = []

    def both(items, join=0.0):
        got = order_cuts(items, join)
        seen.append((len(items), same(got, order_by_loops(items, join))))
        return got
    monkeypatch.setattr(pencil_program, "order_cuts", both)
    part = cadcnc.load_step(FIXTURES / "step_slot.step")
    program = cadcnc.run(part, Job(Tool(3.0, 0.0), 1500.0, 0.004, Pencil(None, "climb")),
                         processes=1)
    assert program.cuts
    assert seen and all(ok for _, ok in seen), seen
    assert max(n for n, _ in seen) >= 2
