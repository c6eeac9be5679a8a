"""The compiled stepper (cadcnc.interp.compiled) against the plain-Python reference.

Every fixture pair's path is computed by both (the reference evaluates with OCCT, the
compiled kernel with its own evaluators and trim grids) and must agree point for point to
1e-9 mm, with the same stop reason, detail and cycle count.
"""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.interp.compiled import CompiledStepper, new_stepper
from cadcnc.interp.stepper import Stepper
from cadcnc.ops.path.pair_path import pair_job, plan_path
from helpers.fixtures import load_fixture
from helpers.pinned import CASES, radius_for


def plan_for(name, i, j):
    part = load_fixture(name)
    s1, s2, job = pair_job(part.face(i), part.face(j), radius=radius_for(name), feed=1500.0,
                           period=0.004)
    return plan_path(s1, s2, job), job


def make(plan, job, compiled, **kw):
    return new_stepper(plan.s1, plan.s2, plan.offsets, plan.start, feed=job.feed,
                   period=job.period, direction=plan.direction, end=plan.end,
                   closed=plan.closed, tol=job.tolerances,
                   check_boundary=plan.check_boundary, compiled=compiled, **kw)


@pytest.mark.parametrize("key, name, i, j", CASES, ids=[c[0] for c in CASES])
def test_compiled_path_agrees_with_the_occt_evaluated_path(key, name, i, j):
    try:
        plan, job = plan_for(name, i, j)
    except Exception as exc:   # refused before computing: nothing to compare
        pytest.skip(f"refused: {type(exc).__name__}")
    ref, fast = make(plan, job, False), make(plan, job, True)
    assert type(ref) is Stepper and type(fast) is CompiledStepper
    ref.run()
    fast.run()
    assert (fast.stop_reason, fast.stop_detail, fast.cycles) == \
        (ref.stop_reason, ref.stop_detail, ref.cycles)
    np.testing.assert_allclose(fast.record.points, ref.record.points, rtol=0, atol=1e-9)
    np.testing.assert_allclose(fast.record.uv, ref.record.uv, rtol=0, atol=1e-9)
    np.testing.assert_allclose(fast.record.normals, ref.record.normals, rtol=0, atol=1e-9)
    np.testing.assert_allclose(fast.record.steps, ref.record.steps, rtol=0, atol=1e-9)
    assert fast.travelled == pytest.approx(ref.travelled, abs=1e-9)
    assert (fast.accuracy_cycles, fast.accuracy_ratio) == pytest.approx(
        (ref.accuracy_cycles, ref.accuracy_ratio), abs=1e-12)


@pytest.mark.parametrize("name, i, j", [("ramp_wall", 3, 7), ("torus_cone", 1, 2)])
def test_step_by_step_with_the_record_off_gives_the_same_increments(name, i, j):
    plan, job = plan_for(name, i, j)
    ref, fast = make(plan, job, False, record=False), make(plan, job, True, record=False)
    feeds = [None, 900.0, 1500.0, 2400.0]     # an override changing every few periods
    k = 0
    while True:
        feed = feeds[(k // 7) % 4]
        a, b = ref.step(feed), fast.step(feed)
        if a is None or b is None:
            assert a is None and b is None
            break
        np.testing.assert_allclose(b, a, rtol=0, atol=1e-9)
        k += 1
    assert (fast.stop_reason, fast.cycles) == (ref.stop_reason, ref.cycles)
    assert fast.record is None and ref.record is None
    np.testing.assert_allclose(fast.p, ref.p, rtol=0, atol=1e-9)


def test_a_surface_without_compiled_data_keeps_the_reference():
    plan, job = plan_for("pocket", 10, 17)

    class Plain:   # the same surface without its compiled data (kernel None: use OCCT)
        kernel = None

        def __init__(self, s):
            self._s = s

        def __getattr__(self, name):
            return getattr(self._s, name)

    st = new_stepper(Plain(plan.s1), plan.s2, plan.offsets, plan.start, feed=job.feed,
                 period=job.period, direction=plan.direction, end=plan.end)
    assert type(st) is Stepper
    st.run()
    assert st.stop_reason == "end"


def test_the_progress_callback_sees_the_compiled_loop():
    plan, job = plan_for("torus_cone", 1, 2)
    seen = []
    st = make(plan, job, True).run(lambda n, total, what: seen.append((n, float(what.split()[0]))),
                                   every=256)  # the record fills (1024 rows) between reports
    assert [n for n, _ in seen] == list(range(256, st.cycles + 1, 256))
    assert all(0 < mm < st.travelled for _, mm in seen)
