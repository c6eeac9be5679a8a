"""The compiled error bounds (cadcnc.interp.bounds_compiled) against the numpy reference.

``Toolpath.bounds`` come from the compiled pass; ``error_bounds.pair_bounds`` is the same
theory vectorised in numpy. On fixture paths both must give the same infinities and NaNs
and agree to round-off: curvatures and torsion to 1e-12 of the path's curvature scale,
every bound (mm) to 1e-12 of its largest finite value or 1e-15 mm, whichever is larger
(numpy's einsum sums with fused multiply-adds on this machine, the compiled loop does not:
tau, a difference of nearly equal products, differs in its last digits, and so does eq11,
which is tau squared: 1e-23 mm apart on bounds of 1e-14 mm).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from cadcnc.interp.error_bounds import pair_bounds
from cadcnc.ops.path.pair_path import pair_job, plan_path, stepper_for
from cadcnc.program.toolpath import toolpath_from_record
from helpers.fixtures import load_fixture

CASES = [("bspline_boss", 4, 5), ("torus_cone", 1, 2), ("crossing_cylinders", 1, 2)]
CURVATURES = ("k", "k_max", "k_min", "tau")


@pytest.mark.parametrize("name, i, j", CASES)
def test_compiled_bounds_agree_with_the_numpy_reference(name, i, j):
    part = load_fixture(name)
    s1, s2, job = pair_job(part.face(i), part.face(j), radius=3.0, feed=1500.0, period=0.004)
    rec = stepper_for(plan_path(s1, s2, job)).run().record
    tp = toolpath_from_record(rec, job, "end")
    f = np.append(tp.commanded[1:], tp.commanded[-1])
    ref = pair_bounds(tp.offsets, tp.points, tp.contacts, tp.normals, rec.ru, rec.rw,
                      rec.forms, tp.tangents, f)
    scale = 1.0 + max(float(np.abs(b.k_max).max() + np.abs(b.k_min).max()) for b in ref)
    for fast, slow in zip(tp.bounds, ref):
        for field in dataclasses.fields(slow):
            x, y = getattr(fast, field.name), getattr(slow, field.name)
            assert x.shape == y.shape == (len(tp),)
            np.testing.assert_array_equal(np.isnan(x), np.isnan(y), err_msg=field.name)
            np.testing.assert_array_equal(np.isposinf(x), np.isposinf(y), err_msg=field.name)
            ok = np.isfinite(y)
            tol = 1e-12 * scale if field.name in CURVATURES else max(
                1e-12 * np.abs(y[ok]).max(), 1e-15)
            np.testing.assert_allclose(x[ok], y[ok], rtol=0, atol=tol, err_msg=field.name)
