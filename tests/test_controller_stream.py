"""The planned stream, judged only by its positions: finite differences against the axis
limits, distance to the kernel's own points, first and last points, and the time where no
limit binds. Nothing here calls the planner's code except to get the stream."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

import cadcnc
from cadcnc.controller import Machine, stream_program
from cadcnc.ops.finish.finish import finish
from cadcnc.ops.path.pair_path import pair_job
from cadcnc.ops.path.pair_program import program_for_job
from cadcnc.ops.pencil.pencil import pencil
from cadcnc.ops.stream_steppers import stepper_factory

from conftest import FIXTURES

SLACK = 1e-6      # relative, on every limit
NEAR = 1e-3       # mm: every position within 1 um of the kernel's path
FEEDS = (None, 10_000.0)   # the program's (default 1500 mm/min) and 10 000 mm/min


def _corner():
    part = cadcnc.load_step(FIXTURES / "bspline_boss.step")
    _, _, job = pair_job(part.face(4), part.face(5), radius=3.0, feed=1500.0, period=0.004)
    return part, program_for_job(part, job)


def _pencil():
    part = cadcnc.load_step(FIXTURES / "step_block.step")
    return part, pencil(part, radius=3.0)


def _finish():
    part = cadcnc.load_step(FIXTURES / "finish_fillet.step")
    return part, finish(part, [6, 3], radius=3.0, stepover=10.0)


@pytest.fixture(scope="module", params=[_corner, _pencil, _finish],
                ids=["corner", "pencil", "finish"])
def program(request):
    part, prog = request.param()
    assert prog.cuts and prog.complete
    return part, prog


def _segments_distance(q: np.ndarray, poly: np.ndarray, piece: float = 0.05) -> np.ndarray:
    """(n,) distance of each point q to the polyline ``poly`` (m, 3): its segments cut to
    at most ``piece`` mm, the exact distance to the 6 whose midpoints are nearest (never
    less than the true distance)."""
    parts = []
    for a, b in zip(poly[:-1], poly[1:]):
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / piece)))
        parts.append(a + np.linspace(0.0, 1.0, n + 1)[:-1, None] * (b - a))
    fine = np.vstack([*parts, poly[-1:]])
    a, b = fine[:-1], fine[1:]
    _, k = cKDTree(0.5 * (a + b)).query(q, k=6)
    a, d = a[k], b[k] - a[k]                                   # (n, 6, 3)
    t = np.clip(((q[:, None] - a) * d).sum(axis=2) / np.maximum((d * d).sum(axis=2), 1e-300),
                0.0, 1.0)
    return np.linalg.norm(q[:, None] - (a + t[..., None] * d), axis=2).min(axis=1)


def _over_limits(x: np.ndarray, m: Machine) -> int:
    """Periods over any axis's velocity, acceleration or jerk limit (finite differences)."""
    ts, bad = m.period, 0
    for k, lim in ((1, m.max_velocity), (2, m.max_acceleration), (3, m.max_jerk)):
        d = np.abs(np.diff(x, k, axis=0)) / ts ** k
        bad += int((d > np.asarray(lim) * (1.0 + SLACK)).any(axis=1).sum())
    return bad


@pytest.mark.parametrize("feed", FEEDS, ids=["default-feed", "10000"])
def test_stream_within_limits_on_the_path(program, feed):
    part, prog = program
    m = Machine.default()
    x = stream_program(prog, m, stepper_factory(part), feed=feed).positions
    assert x.shape[1] == 3 and x.dtype == np.float64
    assert _over_limits(x, m) == 0
    first, last = prog.segments[0].points[0], prog.segments[-1].points[-1]
    assert np.array_equal(x[0], first) and np.array_equal(x[-1], last)
    assert _segments_distance(x, prog.all_moves()).max() <= NEAR
    # the constant feed does exceed them (what the plan is for)
    flat = stream_program(prog, m, stepper_factory(part), feed=feed, planned=False).positions
    assert _over_limits(flat, m) > 0


def test_no_cost_where_nothing_limits(program):
    """With limits far above what the program asks, the planned stream ends within one
    period of the time at the programmed feed (rapids then take no time)."""
    part, prog = program
    fast = 1e6   # mm/s: rapids at this speed, reached in 1e-8 s
    m = Machine(0.001, (fast,) * 3, (fast * 1e8,) * 3, (fast * 1e14,) * 3)
    stream = stream_program(prog, m, stepper_factory(part))
    feed = prog.job.feed / 60.0
    at_feed = (prog.cut_length + sum(s.feed_length for s in prog.links)) / feed
    rapids = sum(s.length - s.feed_length for s in prog.links) / fast
    assert abs(stream.periods * m.period - (at_feed + rapids)) <= m.period
    assert _over_limits(stream.positions, m) == 0
