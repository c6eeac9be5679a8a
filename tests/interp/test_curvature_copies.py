"""The curvature formulas exist three times; this ties the fast copies to the reference.

- ``cadcnc.geometry.differential``: the reference (numpy, one point, readable);
- ``cadcnc.interp.cycle.Contact``: float tuples for the per-cycle hot path;
- ``cadcnc.interp.error_bounds.surface_curvatures``: vectorised over a whole path.

On every face of several fixtures, at random parameter points and random tangent
directions, all three must give the same tangent coordinates, normal curvature,
principal curvatures and |geodesic torsion|, to 1e-9 relative to the surface's
curvature scale (they are the same algebra in a different order).
"""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.geometry import differential as dg
from cadcnc.interp.cycle import Contact
from cadcnc.interp.error_bounds import surface_curvatures
from helpers.fixtures import load_fixture

FIXTURES = ["bspline_boss", "torus_cone", "crossing_cylinders", "ellipse_pocket", "dome_pole"]


def samples(face, rng, n=12):
    """(u, w) points inside the face's parameter box, away from singular points."""
    (u0, u1), (w0, w1) = face.u_range, face.w_range
    out = []
    for u, w in zip(rng.uniform(u0, u1, 4 * n), rng.uniform(w0, w1, 4 * n)):
        if not face.is_singular(u, w):
            d = face.derivatives(u, w)
            if face.singularity(d.ru, d.rw) > 1e-3:
                out.append((u, w))
        if len(out) == n:
            break
    return out


@pytest.mark.parametrize("name", FIXTURES)
def test_three_curvature_implementations_agree(name):
    part = load_fixture(name)
    rng = np.random.default_rng(7)
    checked = 0
    for face in part.faces:
        for u, w in samples(face, rng):
            d = face.derivatives(u, w)
            n = face.normal(u, w)
            ff = dg.fundamental_forms(d.ru, d.rw, d.ruu, d.ruw, d.rww, n)
            t = rng.normal(size=3)
            t -= (t @ n) * n
            t /= np.linalg.norm(t)
            a, b = dg.tangent_coordinates(ff, d.ru, d.rw, t)
            k_ref = dg.normal_curvature(ff, a, b)
            pc = dg.principal_curvatures(ff, d.ru, d.rw)
            tau_ref = dg.geodesic_torsion(pc, t)
            scale = 1.0 + abs(pc.k_max) + abs(pc.k_min)

            c = Contact(face, 3.0, u, w)
            assert c.tangent_coords(tuple(t)) == pytest.approx((a, b), rel=1e-9, abs=1e-12)
            assert abs(c.curvature(tuple(t)) - k_ref) <= 1e-9 * scale

            forms = np.array([[ff.E, ff.F, ff.G, ff.L, ff.M, ff.N]])
            k, k_max, k_min, tau = surface_curvatures(d.ru[None], d.rw[None], n[None], forms,
                                                      t[None])
            assert abs(k[0] - k_ref) <= 1e-9 * scale
            assert abs(k_max[0] - pc.k_max) <= 1e-9 * scale
            assert abs(k_min[0] - pc.k_min) <= 1e-9 * scale
            assert abs(abs(tau[0]) - abs(tau_ref)) <= 1e-9 * scale
            checked += 1
    assert checked >= 3 * len(part.faces)
