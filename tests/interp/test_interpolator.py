"""The direct interpolator against closed forms and OCCT (issue: the paper's cycle)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from OCP.BRep import BRep_Tool
from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve, GeomAPI_ProjectPointOnSurf
from OCP.gp import gp_Pnt

import cadcnc
from cadcnc.core.tolerances import DEFAULT
from cadcnc.interp.compiled import new_stepper
from cadcnc.interp.cycle import CLOSED, END
from cadcnc.interp.stepper import Tangency
from cadcnc.ops.path.pair_path import (
    intersection_path,
    intersection_paths,
    pair_job,
    plan_path,
    stepper_for,
)
from helpers.fixtures import CONCAVE_PAIRS, load_fixture

FEED, PERIOD = 1500.0, 0.004      # the paper's example: f = 0.1 mm
R = 3.0
# the paper's method alone: an accuracy so loose that the stepper never shortens a step
# (the tests that measure the method's order in f need the steps they command)
RAW = replace(DEFAULT, accuracy=10.0)


def surface_deviation(face, points, offset):
    """Signed (distance to the face's surface by OCCT projection) - offset, per point (mm)."""
    surf = face.geom_surface
    return np.array([GeomAPI_ProjectPointOnSurf(gp_Pnt(*p), surf).LowerDistance() - offset
                     for p in points])


def crossing_deviation(points, r_prime, A=20.0, B=10.0):
    """Closed form: distance of each centre from the offset cylinders y^2+z^2=(A+R')^2 and
    x^2+y^2=(B+R')^2 (crossing_cylinders fixture)."""
    P = np.asarray(points)
    return np.maximum(np.abs(np.hypot(P[:, 1], P[:, 2]) - (A + r_prime)),
                      np.abs(np.hypot(P[:, 0], P[:, 1]) - (B + r_prime)))


def path_for(name, i, j, **kw):
    part = load_fixture(name)
    args = dict(radius=R, feed=FEED, period=PERIOD) | kw
    return intersection_path(part.face(i), part.face(j), **args)


# -- crossing cylinders: closed form --------------------------------------------------------
@pytest.mark.parametrize("edge", [0, 1])
def test_crossing_cylinders_closed_form_at_paper_step(edge):
    tp = path_for("crossing_cylinders", 1, 2, edge=edge)
    assert tp.stop_reason == END
    assert crossing_deviation(tp.points, R).max() <= 1e-4
    f = FEED * PERIOD / 60
    steps = tp.steps[1:]
    assert np.all(np.abs(steps[:-1] / f - 1) <= 1e-3)  # every step f within 0.1 %
    assert 0 < steps[-1] <= f * (1 + 1e-3)              # the last one may be shorter


def test_crossing_cylinders_error_is_second_order_in_step():
    worst = []
    for f in (0.4, 0.2, 0.1, 0.05):
        tp = path_for("crossing_cylinders", 1, 2, feed=f * 60 / PERIOD, tol=RAW)
        assert tp.accuracy_cycles == 0
        worst.append(crossing_deviation(tp.points, R).max())
    ratios = np.array(worst[:-1]) / np.array(worst[1:])
    assert np.all((3.0 <= ratios) & (ratios <= 5.0)), (worst, ratios)


def test_allowance_moves_the_path_out_by_C():
    tp = path_for("crossing_cylinders", 1, 2, allowance=0.5)
    assert crossing_deviation(tp.points, R + 0.5).max() <= 1e-4


# -- every fixture pair against OCCT projections and the paper's bound -----------------------
PAIRS = [p for p in CONCAVE_PAIRS if p[0] in {
    "crossing_cylinders", "bspline_boss", "sphere_cylinder", "torus_cone", "pocket",
    "fillet_block"}]


@pytest.mark.parametrize("name,i,j", PAIRS, ids=[f"{n}-{i}-{j}" for n, i, j in PAIRS])
def test_every_pair_within_1um_of_both_offset_surfaces(name, i, j):
    part = load_fixture(name)
    for tp in intersection_paths(part.face(i), part.face(j), radius=R, feed=FEED,
                                        period=PERIOD):
        assert tp.stop_reason in (END, CLOSED), tp.stop_detail
        f = FEED * PERIOD / 60
        for side, n in enumerate((i, j)):
            dev = np.abs(surface_deviation(part.face(n), tp.points, R))
            assert dev.max() < 1e-3, (n, dev.max())
            # the paper's steady-state bound (eq. 16) for the step into each point
            bound = tp.bounds[side].eq16[:-1]
            over = dev[1:] > bound
            b = tp.bounds[side]
            # umbilic to rounding: sqrt(H^2 - K) turns 1e-16 noise into ~1e-9 1/mm
            umbilic = (np.abs(b.k_max - b.k_min) < 1e-6 * np.abs(b.k))[:-1]
            # where the surface is umbilic (sphere) the bound's leading term vanishes and what
            # remains is the O(f^4) linearisation of eq. 4 (docs/method.md)
            assert not np.any(over & ~umbilic), (n, np.nonzero(over & ~umbilic)[0][:5])
            assert np.all(dev[1:][umbilic] <= 10 * f ** 4 * np.abs(b.k[:-1][umbilic]) ** 3
                          + 1e-12)


def test_umbilic_excess_is_fourth_order():
    """On the sphere the paper's bound is 0; the measured deviation scales as f^4."""
    part = load_fixture("sphere_cylinder")
    worst = []
    for f in (0.4, 0.2):
        tp = path_for("sphere_cylinder", 1, 2, feed=f * 60 / PERIOD, tol=RAW)
        worst.append(np.abs(surface_deviation(part.face(1), tp.points, R)).max())
    assert 12.0 < worst[0] / worst[1] < 20.0


# -- stability ----------------------------------------------------------------------------
@pytest.mark.parametrize("name,i,j", [("crossing_cylinders", 1, 2), ("bspline_boss", 4, 5),
                                      ("torus_cone", 1, 2)])
def test_initial_error_decays_to_steady_state(name, i, j):
    part = load_fixture(name)
    plan = plan_path(*pair_job(part.face(i), part.face(j), radius=R, feed=FEED, period=PERIOD))
    n1 = plan.s1.normal(*plan.start.uv1)
    n2 = plan.s2.normal(*plan.start.uv2)
    off = (n1 - n2) / np.linalg.norm(n1 - n2) * 0.05      # 0.05 mm off the true tangency
    start = Tangency(tuple(np.array(plan.start.p) + off), plan.start.uv1, plan.start.uv2)
    stepper = stepper_for(replace(plan, start=start), max_cycles=100, record=True,
                          check_cycles=False).run()
    from cadcnc.program.toolpath import toolpath_from_record

    tp = toolpath_from_record(stepper.record, plan.job, stepper.stop_reason)
    for b in tp.bounds:
        assert b.eps[0] == pytest.approx(0.05, rel=1e-6)
        settled = np.nonzero(b.eps <= b.eps_ss)[0]
        assert len(settled) and settled[0] <= 3          # measured: 1 cycle
        assert np.all(b.eps[settled[0]:] <= b.eps_ss[settled[0]:])  # and stays there


# -- radius 0: the path is the part's own edge ----------------------------------------------
@pytest.mark.parametrize("name,i,j", [("crossing_cylinders", 1, 2), ("bspline_boss", 4, 5),
                                      ("sphere_cylinder", 1, 2)])
def test_radius_zero_traces_the_shared_edge(name, i, j):
    part = load_fixture(name)
    for k, tp in enumerate(intersection_paths(part.face(i), part.face(j), radius=0.0,
                                                     feed=FEED, period=PERIOD)):
        edge = [e for e in part.shared_edges(i, j) if e.edge_class == "concave"][k]
        curve = BRep_Tool.Curve_s(edge.edge, 0.0, 0.0)
        dist = [GeomAPI_ProjectPointOnCurve(gp_Pnt(*p), curve).LowerDistance()
                for p in tp.points]
        assert max(dist) < 1e-4, max(dist)       # measured: docs/method.md
        assert tp.length == pytest.approx(edge.length, rel=2e-3)


# -- seams ----------------------------------------------------------------------------------
@pytest.mark.parametrize("name,i,j", [("sphere_cylinder", 1, 2), ("bspline_boss", 4, 5)])
def test_crossing_a_periodic_seam_is_seamless(name, i, j):
    tp = path_for(name, i, j)
    assert tp.stop_reason == CLOSED
    side = 1  # the cylinder: its u wraps at the seam somewhere along a closed loop
    u = tp.uv[:, side, 0]
    assert np.any(np.abs(np.diff(u)) > math.pi)          # the seam was crossed ...
    jumps = np.linalg.norm(np.diff(tp.contacts[:, side], axis=0), axis=1)
    assert jumps.max() < 0.2                               # ... without a jump in space
    assert np.all(tp.steps[1:-1] == pytest.approx(0.1, rel=1e-3))


# -- the stepper: one period at a time ------------------------------------------------------
def test_whole_path_is_the_stepper_loop():
    part = load_fixture("crossing_cylinders")
    tp = path_for("crossing_cylinders", 1, 2)
    st = cadcnc.make_stepper(part.face(1), part.face(2), radius=R, feed=FEED, period=PERIOD)
    p = np.array(tp.points[0])
    for dp in iter(st.step, None):
        p = p + dp
    assert st.stop_reason == tp.stop_reason and st.cycles == len(tp) - 1
    np.testing.assert_allclose(p, tp.points[-1], atol=1e-9)


def test_feed_override_changes_the_step_while_running():
    part = load_fixture("crossing_cylinders")
    st = cadcnc.make_stepper(part.face(1), part.face(2), radius=R, feed=FEED, period=PERIOD,
                             tol=RAW)
    lengths = []
    for k in range(60):
        feed = FEED * (0.5 if k < 20 else 1.0 + k / 40)  # override 50 %, then a ramp
        dp = st.step(feed)
        lengths.append((np.linalg.norm(dp), feed * PERIOD / 60))
    got, want = np.array(lengths).T
    np.testing.assert_allclose(got, want, rtol=1e-3)
    with pytest.raises(cadcnc.InputError, match="feed"):
        st.step(-5)


def test_accuracy_caps_a_feed_override_and_counts_it():
    """An override past what the path's curvature allows is shortened, like a feed limit."""
    part = load_fixture("crossing_cylinders")
    st = cadcnc.make_stepper(part.face(1), part.face(2), radius=R, feed=FEED, period=PERIOD)
    for _ in range(10):
        assert np.linalg.norm(st.step()) == pytest.approx(0.1, rel=1e-3)
    assert st.accuracy_cycles == 0
    steps = [np.linalg.norm(st.step(FEED * 4)) for _ in range(10)]  # 0.4 mm asked
    assert st.accuracy_cycles == 10 and 0.4 * st.accuracy_ratio == pytest.approx(min(steps),
                                                                                 rel=1e-3)
    assert max(steps) < 0.3
    np.testing.assert_allclose(st.record.ratio[11:], np.array(steps) / 0.4, rtol=1e-3)


# -- the math does not need OCCT ------------------------------------------------------------
class AnalyticCylinder:
    """A plain-Python cylinder r(u, w) = c + a (cos u e1 + sin u e2) + w axis."""

    normal_sign = 1.0

    def __init__(self, radius, axis, e1):
        self.a = radius
        self.ax, self.e1 = np.array(axis, float), np.array(e1, float)
        self.e2 = np.cross(self.ax, self.e1)

    def derivative_tuples(self, u, w):
        a, c, s = self.a, math.cos(u), math.sin(u)
        r = a * (c * self.e1 + s * self.e2) + w * self.ax
        ru = a * (-s * self.e1 + c * self.e2)
        ruu = -a * (c * self.e1 + s * self.e2)
        z = (0.0, 0.0, 0.0)
        return tuple(r), tuple(ru), tuple(self.ax), tuple(ruu), z, z

    def wrap(self, u, w):
        return u % (2 * math.pi), w

    def classify(self, u, w):
        return "inside"


def test_interpolator_on_plain_python_surfaces_without_occt():
    from cadcnc.interp.tangency import solve_tangency

    A, B, Rp = 20.0, 10.0, 3.0
    s1 = AnalyticCylinder(A, (1, 0, 0), (0, 1, 0))   # axis X
    s2 = AnalyticCylinder(B, (0, 0, 1), (1, 0, 0))   # axis Z
    x0 = B + Rp
    start = solve_tangency(s1, s2, (Rp, Rp), (math.pi / 2, x0 - 1), (0.1, 15.0),
                           anchor=(x0, 0.0, math.sqrt((A + Rp) ** 2)), direction=(0, 1, 0))
    st = new_stepper(s1, s2, (Rp, Rp), start, feed=FEED, period=PERIOD, direction=(0, 1, 0),
                 closed=True).run()
    assert st.stop_reason == CLOSED
    pts = st.record.points
    assert crossing_deviation(pts, Rp, A, B).max() <= 1e-4
