"""The polish's compiled D2 gives OCCT's numbers (BRepAdaptor_Surface::D2, point by point)."""

from __future__ import annotations

import numpy as np

import cadcnc
from cadcnc.ops.finish.polish import face_derivatives
from helpers.fixtures import FIXTURES


def test_compiled_derivatives_are_occts():
    part = cadcnc.load_step(FIXTURES / "finish_slab.step")
    for k in (5, 1):                      # the B-spline top, an extruded side
        face = part.face(k)
        rng = np.random.default_rng(k)
        uv = np.c_[rng.uniform(*face.u_range, 200), rng.uniform(*face.w_range, 200)]
        got = face_derivatives(face, uv)
        want = np.array([face.derivative_tuples(u, w) for u, w in uv]).reshape(-1, 6, 3)
        assert face.kernel is not None
        assert np.abs(got - want).max() < 1e-9
