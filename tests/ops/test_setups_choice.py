"""The setups chosen from estimates of each candidate's reach (issue 37, item 4):
:func:`cadcnc.ops.pencil.fewest_setups.choose` computes the chosen candidates only, and
where every estimate holds its program's reach, chooses what the programs alone choose."""

from __future__ import annotations

import random

import pytest

from cadcnc.ops.pencil.fewest_setups import _fewest, choose

PAIRS = [(1, 2), (3, 4), (5, 6)]


def random_reach(rng: random.Random, n: int) -> list[set]:
    """``n`` candidates' program reach: random positions (pair, index) of PAIRS."""
    return [{(rng.choice(PAIRS), rng.randrange(12)) for _ in range(rng.randrange(0, 20))}
            for _ in range(n)]


def run_choose(estimates: list[set], actual: list[set], looked_at: list[set] | None = None):
    """choose() with programs reaching ``actual`` and closer looks giving ``looked_at``
    (default: the program's reach on that pair); its result and the candidates computed."""
    looked_at = actual if looked_at is None else looked_at
    computed: list[int] = []

    def compute(k: int) -> set:
        computed.append(k)
        return set(actual[k])

    def look(k: int, pair) -> set:
        return {key for key in looked_at[k] if key[0] == pair}

    return choose([set(e) for e in estimates], compute, look), computed


@pytest.mark.parametrize("seed", range(40))
def test_supersets_choose_as_the_programs_do(seed):
    rng = random.Random(seed)
    actual = random_reach(rng, 6)
    extra = random_reach(rng, 6)
    estimates = [a | (e if rng.random() < 0.5 else set()) for a, e in zip(actual, extra)]
    (chosen, checked, universe), computed = run_choose(estimates, actual)
    universe_all = set().union(*actual)
    assert universe == universe_all
    assert (chosen, checked) == _fewest(actual, universe_all)
    assert len(computed) == len(set(computed))          # each program computed once
    assert set(chosen) <= set(computed)


@pytest.mark.parametrize("seed", range(20))
def test_exact_estimates_compute_the_chosen_only(seed):
    actual = random_reach(random.Random(seed), 6)
    (chosen, _, _), computed = run_choose(actual, actual)
    assert sorted(computed) == sorted(chosen)


def test_a_closer_look_spares_a_program():
    """Candidate 0's samples claim a position (5) its program does not reach, and so do
    candidate 1's; a closer look at that pair finds candidate 1 does not reach it either:
    candidate 1 is never computed."""
    actual = [{((1, 2), 0), ((1, 2), 1)}, {((1, 2), 0)}]
    estimates = [actual[0] | {((1, 2), 5)}, actual[1] | {((1, 2), 5)}]
    (chosen, _, universe), computed = run_choose(estimates, actual)
    assert chosen == [0] and universe == actual[0]
    assert computed == [0]


def test_an_overestimated_choice_is_computed_and_chosen_again():
    """Candidate 0's samples claim all three positions, its program reaches one; candidate
    2's samples miss position 2, which its program reaches: the closer look at candidate 2
    (chosen once 0 falls short) finds it, and candidate 2 alone is chosen."""
    actual = [{((1, 2), 0)}, {((1, 2), 1)}, {((1, 2), 0), ((1, 2), 1), ((1, 2), 2)}]
    estimates = [{((1, 2), k) for k in range(3)}, actual[1], {((1, 2), 0), ((1, 2), 1)}]
    (chosen, _, universe), computed = run_choose(estimates, actual)
    assert chosen == [2] and universe == actual[2]
    assert computed == [0, 2]


@pytest.mark.slow
def test_six_pockets_choose_every_side_once():
    """fixtures/six_pockets.step (a pocket on each side, each reachable from its own side
    only): the six setups, in candidate order (equal reach), each program computed once,
    its samples reaching what it reaches."""
    import cadcnc
    from cadcnc.core.job import Job, Pencil, Tool
    from cadcnc.ops.pencil.fewest_setups import AUTO_ORDER, pencil_setups
    from helpers.six_pockets import STEP, R

    part = cadcnc.load_step(STEP)
    result = pencil_setups(part, Job(Tool(R), 1500.0, 0.004, Pencil()), "auto")
    assert [r.setup.name for r in result.runs] == list(AUTO_ORDER)
    assert all(r.computed for r in result.candidates)
    for r in result.runs:
        assert r.reached == r.sampled == result.reach[r.setup.name] > 0
        assert r.assigned == r.reached   # no side reaches another's corner
    assert sum(r.assigned for r in result.runs) == result.positions
