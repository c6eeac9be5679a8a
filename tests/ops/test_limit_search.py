"""Stretch limits by a root search on the failing rule's margin (issue 37, item 3).

Against the reference it replaced (bisection until the two sides' centres are 1e-7 mm
apart, ``bisect_limit``, computed here too): on fixtures with a limit of every rule with
a margin (collision, tangent, curvature) and without (boundary), the same stretches and
rules, every limit within ``Tolerances.stretch_limit`` of the reference's and feasible by
the judge, for far fewer samples. Then the search itself on closed forms, kernel-free.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pytest

import cadcnc
from cadcnc.core.tolerances import DEFAULT
from cadcnc.guard import guard_for
from cadcnc.ops.path import stretches
from cadcnc.ops.path.feasibility import FEASIBLE, ONE_SIDED, Feasibility
from cadcnc.ops.path.limit_search import limit_samples, root_limit
from cadcnc.ops.path.pair_path import pair_job
from cadcnc.ops.path.stretches import LIMIT_TOL, SPACING, bisect_limit, pair_stretches
from helpers.fixtures import FIXTURES
from helpers.programs import pencil_run

TOL = DEFAULT.stretch_limit
CASES = [   # (fixture, radius, pairs): every rule's limits
    ("step_slot", 3.0, [(12, 13), (23, 24), (23, 27), (26, 27)]),   # boundary, collision
    ("stretch_shelf", 3.0, None),      # collision under a shelf (ball and shank)
    ("stretch_sloped", 3.0, None),     # boundary across a slanted wall top
    ("stretch_boss", 3.0, None),       # boundary on a closed edge
    ("equal_cylinders", 3.0, [(1, 2)]),   # tangent
    ("ellipse_pocket", 5.0, [(7, 8)]),    # curvature
]
_cache: dict = {}


def searched(name: str, radius: float, pairs, locate) -> list:
    """[(pair, edges, samples per limit, judge)] of a fixture's pairs, limits by
    ``locate`` (the root search or the reference bisection)."""
    part = cadcnc.load_step(FIXTURES / f"{name}.step")
    if pairs is None:
        pairs = part.concave_pairs()
    out = []
    for i, j in pairs:
        s1, s2, job = pair_job(part.face(i), part.face(j), radius=radius, feed=1500.0,
                               period=0.004)
        feas = Feasibility(s1, s2, job, guard_for(part, (i, j), job))
        counts = []

        def counted(f, curve, good, bad):
            n0 = f.samples
            got = locate(f, curve, good, bad)
            counts.append(f.samples - n0)
            return got

        old, stretches.locate_limit = stretches.locate_limit, counted
        try:
            found = pair_stretches(s1, s2, job, feas=feas)
        finally:
            stretches.locate_limit = old
        out.append(((i, j), found, counts, feas))
    return out


def both(name, radius, pairs):
    if name not in _cache:
        _cache[name] = (searched(name, radius, pairs, stretches.locate_limit),
                        searched(name, radius, pairs, bisect_limit))
    return _cache[name]


@pytest.mark.parametrize("name,radius,pairs", CASES, ids=[c[0] for c in CASES])
def test_limits_within_the_tolerance_of_the_bisection_and_feasible(name, radius, pairs):
    root, ref = both(name, radius, pairs)
    rules = set()
    for (pair, edges, _, feas), (_, ref_edges, _, _) in zip(root, ref):
        assert [len(e.stretches) for e in edges] == [len(e.stretches) for e in ref_edges]
        for edge, ref_edge in zip(edges, ref_edges):
            for st, ref_st in zip(edge.stretches, ref_edge.stretches):
                for lim, ref_lim in ((st.start, ref_st.start), (st.end, ref_st.end)):
                    assert lim.rule == ref_lim.rule, (pair, lim, ref_lim)
                    rules.add(lim.rule)
                    gap = float(np.linalg.norm(np.subtract(lim.p, ref_lim.p)))
                    assert gap <= TOL + LIMIT_TOL, (pair, lim, ref_lim, gap)
                    # the feasible side: the judge (a fresh verdict) keeps the limit
                    assert feas.judge(lim.tangency)[0] == FEASIBLE, (pair, lim)
    assert rules - {"search", "closed"}, "the fixture has no located limit"


@pytest.mark.parametrize("name,radius,pairs", CASES, ids=[c[0] for c in CASES])
def test_fewer_samples_per_limit(name, radius, pairs):
    """The reference bisects every limit 0.4 mm down to 1e-7 mm (22 samples); the search
    takes at most 6 on a rule with a margin (collision and tangent: 2-4 here), and at
    most a bisection to the tolerance (12) on the boundary rule (1 where a contact leaves
    its face at the edge's end). The ellipse's curvature limits, where the intersection
    curve jumps branch and no two centres come within the tolerance, take what the
    bisection takes there (to 1e-12 mm of arc length), about half as many."""
    root, ref = both(name, radius, pairs)
    for (_, edges, counts, _), (_, _, ref_counts, _) in zip(root, ref):
        assert len(counts) == len(ref_counts)
        limits = [lim for e in edges for st in e.stretches for lim in (st.start, st.end)
                  if lim.rule not in ("search", "closed")]
        assert len(limits) == len(counts)
        for lim, n, n_ref in zip(limits, counts, ref_counts):
            if name == "ellipse_pocket":
                assert n <= n_ref, (lim, n, n_ref)
            elif lim.rule in ("collision", "tangent"):
                assert n <= 6, (lim, n)
            else:
                assert n <= limit_samples(SPACING, TOL), (lim, n)
            assert n < n_ref


def test_samples_per_limit_in_all():
    """Over every case: at most a third of the bisection's samples."""
    n_root = n_ref = 0
    for name, radius, pairs in CASES:
        root, ref = both(name, radius, pairs)
        n_root += sum(sum(c) for _, _, c, _ in root)
        n_ref += sum(sum(c) for _, _, c, _ in ref)
    assert 3 * n_root <= n_ref, (n_root, n_ref)


# -- the search on closed forms ------------------------------------------------------------

@dataclass
class _Tan:
    p: tuple


@dataclass
class _Sample:
    s: float
    rule: str
    tangency: _Tan | None
    margins: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.rule == FEASIBLE


def judge_of(rules: dict, one_sided=()):
    """A trial judging position s (centre (s, 0, 0)) by ``rules`` {name: margin(s)} in
    order, the first negative failing; a feasible sample's one-sided margins are lower
    bounds (here a tenth of the value), as the guard's are; ``boundary`` is yes/no (its
    sign only, no margin kept), as the trim classifier's is."""
    calls = []

    def trial(s, seed=None):
        calls.append(s)
        margins = {}
        for name, f in rules.items():
            m = f(s)
            if name != "boundary":
                margins[name] = m
            if m < 0.0:
                return _Sample(s, name, _Tan((s, 0.0, 0.0)), margins)
        for name in one_sided:
            margins[name] *= 0.1
        return _Sample(s, FEASIBLE, _Tan((s, 0.0, 0.0)), margins)

    return trial, calls


def check(rules, root, good_s=0.0, bad_s=0.4, one_sided=(), most=6, hints=()):
    trial, calls = judge_of(rules, one_sided)
    good, bad = trial(good_s), trial(bad_s)
    calls.clear()
    lo, hi, used = root_limit(trial, good, bad, TOL, LIMIT_TOL, one_sided, hints)
    assert lo.ok and not hi.ok
    assert abs(hi.s - lo.s) < TOL
    assert min(lo.s, hi.s) - 1e-12 <= root <= max(lo.s, hi.s) + 1e-12   # the root inside
    assert used == len(calls) <= most, calls
    return lo, hi


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_a_smooth_margin_takes_few_trials_either_way(direction):
    root = (-1.5 + (1.5 ** 2 + 4 * 0.2 * 0.3) ** 0.5) / 0.4
    f = (lambda s: 0.3 - 1.5 * s - 0.2 * s * s) if direction > 0 else (
        lambda s: 0.3 - 1.5 * (0.4 - s) - 0.2 * (0.4 - s) ** 2)
    check({"curvature": f}, root if direction > 0 else 0.4 - root,
          *((0.0, 0.4) if direction > 0 else (0.4, 0.0)), most=5)


def test_a_one_sided_margin_uses_its_failing_side():
    """The guard's clearance: a lower bound where clear (a tenth here), exact where it
    fails; slope 0.7 mm per mm of centre."""
    check({"collision": lambda s: 0.7 * (0.25 - s)}, 0.25, one_sided=("collision",), most=4)


def test_a_rule_without_margin_is_bisected_to_the_tolerance():
    rules = {"boundary": lambda s: 1.0 if s < 0.123456 else -1.0}
    check(rules, 0.123456, most=limit_samples(0.4, TOL))
    rules = {"boundary": lambda s: 1.0 if s <= 0.3 else -1.0}   # at a hint: two trials
    check(rules, 0.3, most=2, hints=(0.3,))


def test_another_rule_failing_first_takes_over():
    """The infeasible end fails curvature, but the tangent rule fails nearer: the limit
    is the tangent rule's, found on its margin."""
    rules = {"curvature": lambda s: 0.3 - s, "tangent": lambda s: 0.1 - s}
    lo, hi = check(rules, 0.1, most=7)
    assert hi.rule == "tangent"


def test_one_sided_rules_of_the_judge():
    assert ONE_SIDED == ("collision",)


# -- the programs ----------------------------------------------------------------------------

def test_a_pencil_program_moves_by_less_than_the_gouge_limit(monkeypatch):
    """step_slot's pencil (R 3) with the root search and with the bisection: the same cuts
    (matched by their end points: nearest-neighbour linking may order ties otherwise), each
    end within the limit's accuracy of the other's, far under the gouge limit, and the
    gate's verdict on every cut the same (passed)."""
    from cadcnc.ops.path import stretch_split
    from cadcnc.verification import gouge_gate

    part = cadcnc.load_step(FIXTURES / "step_slot.step")
    now = pencil_run(part, radius=3.0)
    with monkeypatch.context() as m:
        m.setattr(stretches, "locate_limit", bisect_limit)
        m.setattr(stretch_split, "locate_limit", bisect_limit)
        before = pencil_run(cadcnc.load_step(FIXTURES / "step_slot.step"), radius=3.0)
    assert len(now.cuts) == len(before.cuts) and len(now.skipped) == len(before.skipped)

    def ends(cut):
        return np.array([cut.points[0], cut.points[-1]])

    worst = max(min(np.abs(ends(a) - ends(b)).max() for b in before.cuts) for a in now.cuts)
    assert worst <= TOL + LIMIT_TOL < DEFAULT.gouge
    for prog in (now, before):
        moves = prog.all_moves()
        for cut in prog.cuts:
            assert gouge_gate(cut.path, part, moves=moves if cut is prog.cuts[0] else None).ok
