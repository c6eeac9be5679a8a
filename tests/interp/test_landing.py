"""Bounded landing (at most MAX_TRIALS cycles per stop) and the collision guard's hook."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cadcnc.interp.compiled import new_stepper
from cadcnc.interp.cycle import BOUNDARY, COLLISION, STOP_REASONS
from cadcnc.interp.landing import LANDING_TOL, MAX_TRIALS, land
from cadcnc.interp.stepper import Stepper
from cadcnc.ops.path.pair_path import pair_job, plan_path
from helpers.fixtures import load_fixture
from helpers.pinned import CASES, radius_for

F = 0.1  # mm: feed 1500 mm/min, period 4 ms


def counting(trial_of_s):
    calls = []

    def trial(s):
        calls.append(s)
        return trial_of_s(s)
    return trial, calls


@pytest.mark.parametrize("root", [1e-6, 0.3771, 0.5, 0.999999])
@pytest.mark.parametrize("shape", ["linear", "cubic", "steep"])
def test_a_smooth_margin_is_landed_on_its_zero_within_the_tolerance(root, shape):
    g = {"linear": lambda s: root - s,
         "cubic": lambda s: (root - s) * (1.0 + 3.0 * s * s),
         "steep": lambda s: math.tanh(50.0 * (root - s))}[shape]
    trial, calls = counting(lambda s: (g(s) >= 0.0, g(s), False))
    lo, used = land(trial, g(0.0), g(1.0), MAX_TRIALS - 1, LANDING_TOL / F)
    assert used == len(calls) <= MAX_TRIALS - 1
    assert g(lo) >= 0.0                        # lo itself passed
    assert (root - lo) * F <= LANDING_TOL      # and is on the zero to 1e-12 mm of path


@pytest.mark.parametrize("root", [1e-3, 0.3771, 0.75])
def test_a_yes_no_rule_is_bisected_within_the_trial_budget(root):
    trial, calls = counting(lambda s: (s <= root, math.nan, False))
    lo, used = land(trial, math.nan, math.nan, MAX_TRIALS - 1, LANDING_TOL / F)
    assert used == len(calls) == MAX_TRIALS - 1
    assert lo <= root and root - lo <= 2.0 ** -(MAX_TRIALS - 1)


def stepper(name, i, j, guard=None, radius=3.0, compiled=True):
    part = load_fixture(name)
    s1, s2, job = pair_job(part.face(i), part.face(j), radius=radius, feed=1500.0,
                           period=0.004)
    plan = plan_path(s1, s2, job)
    return new_stepper(plan.s1, plan.s2, plan.offsets, plan.start, feed=job.feed,
                   period=job.period, direction=plan.direction, end=plan.end,
                   closed=plan.closed, tol=job.tolerances, check_boundary=plan.check_boundary,
                   guard=guard, compiled=compiled)


def run_counting(st):
    """Run to the stop; the number of trial cycles of each step (the compiled stepper runs
    a step's first trial in the kernel: one more than counted here)."""
    tries, per_step = [0], []
    original = st._try

    def counted(f):
        tries[0] += 1
        return original(f)
    st._try = counted
    while True:
        tries[0] = 0
        dp = st.step()
        per_step.append(tries[0])
        if dp is None:
            return per_step


@pytest.mark.parametrize("key, name, i, j", CASES, ids=[c[0] for c in CASES])
def test_every_fixture_stop_takes_at_most_24_trial_cycles(key, name, i, j):
    try:
        st = stepper(name, i, j, radius=radius_for(name), compiled=False)
    except Exception as exc:   # pairs refused before computing have no stop to land
        pytest.skip(f"refused: {type(exc).__name__}")
    per_step = run_counting(st)
    assert max(per_step) <= MAX_TRIALS
    if st.stop_reason == BOUNDARY:
        assert st.landing_trials == per_step[-2] == MAX_TRIALS   # yes/no rule: bisected
        fast = stepper(name, i, j, radius=radius_for(name))
        assert type(fast) is not Stepper
        fast_steps = run_counting(fast)
        assert fast.landing_trials == fast_steps[-2] + 1 == MAX_TRIALS


class Plane:
    """An obstacle half-space {x . a >= c}: the centre must stay ``gap`` mm before it."""

    def __init__(self, a, c, gap):
        self.a, self.c, self.gap = np.asarray(a, float), c, gap

    def margin(self, p):
        return self.c - self.gap - float(self.a @ p), "ball touches the plane"


class Ball:
    """A spherical obstacle of radius rho: the centre must stay rho + gap from its centre."""

    def __init__(self, centre, rho, gap):
        self.centre, self.rho, self.gap = np.asarray(centre, float), rho, gap

    def margin(self, p):
        return float(np.linalg.norm(np.asarray(p) - self.centre)) - self.rho - self.gap, \
            "ball touches the sphere"


def test_collision_is_a_stop_reason():
    assert COLLISION == "collision" and COLLISION in STOP_REASONS


@pytest.mark.parametrize("compiled", [False, True])
def test_a_plane_across_the_pocket_edge_stops_the_ball_tangent_to_it(compiled):
    # pocket 10/17: the centre runs straight from x = -22 to x = 22 at y = -17, z = 18
    guard = Plane((1.0, 0.0, 0.0), 5.0123456789, 3.0)   # a wall at x = 5.0123456789
    st = stepper("pocket", 10, 17, guard, compiled=compiled)
    per_step = run_counting(st)
    assert st.stop_reason == COLLISION and st.stop_detail == "ball touches the plane"
    last = st.record.points[-1]
    assert last[0] == pytest.approx(5.0123456789 - 3.0, abs=1e-9)   # closed form
    assert np.all(st.record.points[:, 0] <= 5.0123456789 - 3.0)
    assert max(per_step) <= MAX_TRIALS and st.landing_trials <= 4   # secant: few trials
    assert (type(st) is Stepper) == (compiled is False)


@pytest.mark.parametrize("compiled", [False, True])
def test_a_sphere_beside_a_closed_path_stops_it_tangent_to_the_sphere(compiled):
    # sphere_cylinder: the centre runs on a circle of radius 13 about z at z = 30.33
    centre = (13.0 * math.cos(1.0), 13.0 * math.sin(1.0), 30.3315018 + 4.0)
    guard = Ball(centre, 1.5, 3.0)            # its surface is 1 mm off the circle's plane
    st = stepper("sphere_cylinder", 1, 2, guard, compiled=compiled)
    per_step = run_counting(st)
    assert st.stop_reason == COLLISION
    dist = np.linalg.norm(st.record.points - centre, axis=1)
    assert dist[-1] == pytest.approx(4.5, abs=1e-9)
    assert np.all(dist >= 4.5 - 1e-12)
    # where the circle first reaches distance 4.5: closed form in the angle
    x, y, z = st.record.points[-1]
    assert math.hypot(x, y) == pytest.approx(13.0, abs=1e-6)
    # |p - c|^2 = 2 * 13^2 (1 - cos(phi - 1)) + 4^2 (dz = 4 up to the path's 1e-7 height)
    dz = centre[2] - z
    phi = 1.0 - math.acos(1.0 - (4.5 ** 2 - dz ** 2) / (2 * 13.0 ** 2))
    assert math.atan2(y, x) == pytest.approx(phi, abs=1e-9)
    assert max(per_step) <= MAX_TRIALS


@pytest.mark.parametrize("compiled", [False, True])
def test_a_start_already_in_collision_takes_no_step(compiled):
    st = stepper("pocket", 10, 17, Plane((1.0, 0.0, 0.0), -30.0, 3.0), compiled=compiled)
    assert st.step() is None
    assert st.stop_reason == COLLISION and "no step possible" in st.stop_detail


class CountingPlane(Plane):
    """``Plane`` counting its margin calls; with ``budget``: its clearance (a distance)."""

    def __init__(self, *args, budget=False):
        super().__init__(*args)
        self.calls = 0
        if budget:
            self.budget = lambda p: self.c - self.gap - float(self.a @ p)

    def margin(self, p):
        self.calls += 1
        return super().margin(p)


def test_a_guard_budget_spares_its_calls_and_keeps_the_path():
    plain = CountingPlane((1.0, 0.0, 0.0), 5.0123456789, 3.0)
    budgeted = CountingPlane((1.0, 0.0, 0.0), 5.0123456789, 3.0, budget=True)
    a = stepper("pocket", 10, 17, plain).run()
    b = stepper("pocket", 10, 17, budgeted).run()
    assert type(b) is not Stepper  # the compiled stepper
    assert b.stop_reason == COLLISION and b.stop_detail == a.stop_detail
    assert np.array_equal(a.record.points, b.record.points)  # the same commits
    assert b.record.points[-1][0] == pytest.approx(5.0123456789 - 3.0, abs=1e-9)
    assert plain.calls >= a.cycles
    # asked again only when a step leaves the clear ball: about log(distance / f) times
    # while approaching, plus the landing's trials
    assert budgeted.calls < 0.2 * plain.calls, (budgeted.calls, plain.calls)
