"""The OpenCAMLib comparison's own tools (benchmarks/finishing/: freeform_slab.py,
finish_bench_tools.py).

The comparison (benchmarks/finishing/finish_vs_ocl.py) is not part of the suite and needs
opencamlib; what it measures with is checked here: the slab is the graph it claims
(u = x, w = y, hollows wider than the ball), the deviation judge returns a known offset
with its sign (gouge side negative) and applies the "ball wholly over the face" rule at
the distance it states, and the tessellation's vertices lie on the face.
"""

import numpy as np
import pytest

import cadcnc
from benchmarks.finishing import finish_bench_tools as tools
from benchmarks.finishing import finish_vs_ocl
from benchmarks.finishing import freeform_slab as slab

R = 3.0



@pytest.fixture(scope="module")
def top():
    part = cadcnc.Part(slab.slab_shape(), source="freeform slab")
    return part, part.face(slab.top_face_number(part))


def test_the_slab_top_is_the_graph_it_claims(top):
    part, face = top
    assert len(part) == 6 and face.kind == "bspline"
    assert face.u_range == pytest.approx((0.0, slab.LENGTH)) and \
        face.w_range == pytest.approx((0.0, slab.WIDTH))
    rng = np.random.default_rng(1)
    for u, w in rng.uniform((0, 0), (slab.LENGTH, slab.WIDTH), (20, 2)):
        p = face.point(u, w)
        assert p[:2] == pytest.approx((u, w), abs=1e-9)   # u = x, w = y
        assert face.normal(u, w)[2] > 0.5                  # facing up, slopes under 60 deg
    lo, hi = part.bounding_box()
    assert lo == pytest.approx((0, 0, 0), abs=1e-6) and hi[:2] == pytest.approx((80, 60))
    # the ball fits every hollow: its exact offset is a surface the deviation is taken to
    assert slab.min_concave_radius(step=1.0) > 2 * R


def test_the_judge_returns_a_known_offset_with_its_side_and_the_rule(top):
    _, face = top
    judge = tools.FaceDistances([face.topods], R, margin=0.5)
    # centres at R' + delta along the normal above known feet, across the whole pass
    xs = np.linspace(0.2, 79.8, 200)
    delta = 2e-4 * np.sin(xs)               # both sides: gouge (< 0) and leave (> 0)
    y = 30.0
    centres = np.array([face.point(x, y) + (R + d) * face.normal(x, y)
                        for x, d in zip(xs, delta)])
    dev = judge.measure([centres[:100], centres[100:]], check=20)
    np.testing.assert_allclose(dev.signed, delta, atol=1e-9)
    assert dev.check_max < 1e-9 and dev.checked == 20
    # the rule: the ball grown by the margin clear of the face's boundary, measured here
    # to the four sides of the parameter rectangle sampled every 0.04 mm or less
    t = np.linspace(0.0, 1.0, 2001)
    sides = [face.point(u, w) for u, w in
             [*((slab.LENGTH * a, 0.0) for a in t), *((slab.LENGTH * a, slab.WIDTH) for a in t),
              *((0.0, slab.WIDTH * a) for a in t), *((slab.LENGTH, slab.WIDTH * a) for a in t)]]
    sides = np.array(sides)
    clear = np.array([np.linalg.norm(sides - c, axis=1).min() for c in centres])
    assert clear.min() < R + 0.3 and clear.max() > R + 1   # both kinds of centre present
    assert np.all(dev.over[clear > R + 0.5 + 0.02])
    assert not np.any(dev.over[clear < R + 0.5 - 0.02])
    s = dev.summary()
    assert s["gouge"] < -1e-4 and s["leave"] > 1e-4 and s["max"] <= 2e-4 + 1e-9
    assert [len(a) for a, _ in dev.per_line()] == [100, 100]


def test_the_mesh_lies_on_the_face_and_refines_with_the_tolerance(top):
    _, face = top
    coarse, _ = tools.tessellate([face.topods], 1e-1)
    fine, _ = tools.tessellate([face.topods], 3e-2)
    assert len(fine) > 2 * len(coarse)
    vertices = fine.reshape(-1, 3)[::97]
    judge = tools.FaceDistances([face.topods], 0.0)
    d = np.abs(judge.measure([vertices], check=0).signed)
    assert d.max() < 1e-6
    # every triangle faces up, as the face does (orientation kept)
    n = np.cross(fine[:, 1] - fine[:, 0], fine[:, 2] - fine[:, 0])
    assert np.all(n[:, 2] > 0)


def test_every_function_the_comparisons_stopwatch_times_exists():
    """finish_vs_ocl's Stopwatch wraps functions by name: a renamed one would break
    `python -m benchmarks perf` (it imports no opencamlib for this)."""
    with finish_vs_ocl.Stopwatch() as watch:
        assert len(watch.seconds) == len(finish_vs_ocl.Stopwatch.WATCHED)
