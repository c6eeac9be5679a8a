"""The planned stream, judged only by its positions: finite differences against the axis
limits, distance to the kernel's own points, first and last points, and the time where no
limit binds. Nothing here calls the planner's code except to get the stream."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

import cadcnc
from cadcnc.controller import Machine, cut_rows, stream_program
from cadcnc.controller.cut_rows import BLEND
from cadcnc.interp.planned_follow import follow
from cadcnc.ops.finish.shortcut import finish
from cadcnc.ops.path.pair_path import pair_job
from cadcnc.ops.path.pair_program import program_for_job
from cadcnc.ops.stream_steppers import stepper_factory
from helpers.fixtures import FIXTURES
from helpers.programs import pencil_run

pytestmark = pytest.mark.slow  # over about 5 s a test (pyproject.toml)

SLACK = 1e-6      # relative, on every limit
NEAR = 1e-3       # mm: every position within 1 um of the kernel's path
FAST = 10_000.0   # mm/min
FEEDS = (None, FAST)   # the program's (default 1500 mm/min) and 10 000 mm/min


_PARTS: dict = {}


def _part(name: str):
    """The fixture's part, loaded once for the module's programs."""
    if name not in _PARTS:
        _PARTS[name] = cadcnc.load_step(FIXTURES / name)
    return _PARTS[name]


def _corner(feed=1500.0):
    part = _part("bspline_boss.step")
    _, _, job = pair_job(part.face(4), part.face(5), radius=3.0, feed=feed, period=0.004)
    return part, program_for_job(part, job)


def _pencil(feed=None):
    part = _part("step_block.step")
    return part, pencil_run(part, radius=3.0, **({} if feed is None else {"feed": feed}))


def _finish(feed=None):
    part = _part("finish_fillet.step")
    return part, finish(part, [6, 3], radius=3.0, stepover=10.0,
                        **({} if feed is None else {"feed": feed}))


@pytest.fixture(scope="module", params=[_corner, _pencil, _finish],
                ids=["corner", "pencil", "finish"])
def program(request):
    part, prog = request.param()
    assert prog.cuts and prog.complete
    return part, prog


@pytest.fixture(scope="module", params=[_corner, _pencil, _finish],
                ids=["corner", "pencil", "finish"])
def fast_program(request):
    """The same programs computed at 10 000 mm/min (the steps the kernel took at it)."""
    part, prog = request.param(FAST)
    assert prog.cuts and prog.complete and prog.job.feed == FAST
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
    fast = 1e5   # mm/s: rapids at this speed, reached in 1e-4 s (the largest limits a
    m = Machine(0.001, (fast,) * 3, (1e9,) * 3, (1e15,) * 3)   # Machine accepts)
    stream = stream_program(prog, m, stepper_factory(part))
    feed = prog.job.feed / 60.0
    at_feed = (prog.cut_length + sum(s.feed_length for s in prog.links)) / feed
    rapids = sum(s.length - s.feed_length for s in prog.links) / fast
    assert abs(stream.periods * m.period - (at_feed + rapids)) <= m.period
    assert _over_limits(stream.positions, m) == 0


def test_programs_computed_at_10000_stream_within_limits_on_the_path(fast_program):
    """A program computed at 10 000 mm/min (longer steps, the accuracy rule shortening
    some) streamed at its own feed: within every limit, on its path, first and last
    points exact."""
    part, prog = fast_program
    m = Machine.default()
    stream = stream_program(prog, m, stepper_factory(part))
    x = stream.positions
    assert stream.kernel_cuts >= 1
    assert _over_limits(x, m) == 0
    first, last = prog.segments[0].points[0], prog.segments[-1].points[-1]
    assert np.array_equal(x[0], first) and np.array_equal(x[-1], last)
    assert _segments_distance(x, prog.all_moves()).max() <= NEAR


def _python_driven(stepper, piece, s, period, blend, landing=1e-6):
    """The stream's loop as it ran before the kernel followed the plan: one
    ``stepper.step(feed)`` call per period from Python (the reference), the target
    moving onto the distance left over the last ``blend`` mm."""
    end = piece.points[-1]
    ds = np.diff(np.r_[0.0, s])
    kappa = np.interp(s, piece.s, piece.kappa)
    left = piece.length - s
    x = np.clip(1.0 - left / blend, 0.0, 1.0)
    weight = x ** 3 * (10.0 - 15.0 * x + 6.0 * x * x)
    k_end, to_feed = float(piece.kappa[-1]), 60.0 / period
    (ex, ey, ez), (x, y, z) = map(float, end), map(float, stepper.p)
    for _ in range(cut_rows.SETTLE_STEPS):   # the start settled onto the kernel's path
        dp = stepper.step(cut_rows.SETTLE_STEP * to_feed)
        if dp is None:
            break
        x, y, z = x + dp[0], y + dp[1], z + dp[2]
        if math.sqrt(dp[0] ** 2 + dp[1] ** 2 + dp[2] ** 2) <= cut_rows.SETTLE_MIN:
            break
    chords = np.cumsum(np.concatenate(([stepper.travelled],
                                       ds * (1.0 - kappa ** 2 * ds ** 2 / 24.0))))[1:]
    rows = []
    for n, target in enumerate(chords.tolist()):
        if stepper.stop_reason is None:
            f, w = target - stepper.travelled, weight[n]
            if w > 0.0:
                d = math.sqrt((ex - x) ** 2 + (ey - y) ** 2 + (ez - z) ** 2)
                f = (1.0 - w) * f + w * (d * (1.0 + k_end * k_end * d * d / 24.0) - left[n])
                if left[n] <= 0.0:
                    f = max(f, d * (1.0 + landing) + 1e-12)
            if f > 0.0:
                dp = stepper.step(f * to_feed)
                if dp is not None:
                    x, y, z = x + dp[0], y + dp[1], z + dp[2]
        rows.append((x, y, z))
    return np.array(rows)


def test_the_kernel_loop_streams_what_the_python_loop_did(fast_program):
    """Every cut's rows of the stream (the kernel following the plan in its compiled
    loop) equal, to 1e-12 mm, the positions of the same plan driven from Python."""
    part, prog = fast_program
    m = Machine.default()
    factory = stepper_factory(part)
    stream = stream_program(prog, m, factory)
    rows, s = stream.plan.targets()
    compared = 0
    for j, piece in enumerate(stream.plan.pieces):
        sel = np.flatnonzero(rows == j)
        stepper = None if piece.cut is None else factory(piece.cut, prog.cuts[piece.cut],
                                                         m.period)
        if stepper is None or not len(sel) or j == 0:
            continue   # (row 0 is set to the program's first point)
        ref = _python_driven(stepper, piece, s[sel], m.period, min(BLEND, piece.length))
        assert np.abs(stream.positions[sel] - ref).max() <= 1e-12
        compared += len(sel)
    assert compared > 500


def test_the_accuracy_rule_shortens_the_steps_the_plan_commands(fast_program):
    """Steps commanded by the plan longer than the accuracy rule allows are shortened in
    the compiled loop as from Python: the same shortened cycles, the same positions."""
    part, prog = fast_program
    k = max(range(len(prog.cuts)), key=lambda i: prog.cuts[i].path.accuracy_cycles)
    cut = prog.cuts[k]
    factory = stepper_factory(part)
    period = prog.job.period
    step = FAST / 60.0 * period   # the program's own step: shortened where it was
    n = int(len(cut.path.points) * 0.8)   # stops short of the end
    plan = np.zeros((n, 3))
    plan[:, 0] = step * np.arange(1, n + 1)
    compiled = factory(k, cut, period)
    out = follow(compiled, plan, cut.path.points[-1], 0.0, 1e-6)
    python = factory(k, cut, period)
    ref = []
    for target in plan[:, 0]:
        python.step((target - python.travelled) * 60.0 / period)
        ref.append(python.p)
    assert compiled.accuracy_cycles == python.accuracy_cycles
    assert (compiled.accuracy_cycles > 0) == (cut.path.accuracy_cycles > 0)   # pencil: none
    assert np.abs(out - np.array(ref)).max() <= 1e-12


def test_on_plan_hears_the_plan_before_any_position():
    """``on_plan`` gets the plan the stream is made of (the pipeline counts and bounds the
    periods from it: one plan, not two), before the kernel computes a position: raising
    there stops the stream with no stepper made."""
    part, program = _corner()
    heard, made = [], []

    def steppers(k, seg, period):
        made.append(k)
        return stepper_factory(part)(k, seg, period)

    s = stream_program(program, Machine.default(), steppers, on_plan=heard.append)
    assert heard and heard[-1] is s.plan and heard[-1].periods == s.periods
    made.clear()

    def refuse(plan):
        raise RuntimeError(f"{plan.periods} periods")

    with pytest.raises(RuntimeError, match=f"{s.periods} periods"):
        stream_program(program, Machine.default(), steppers, on_plan=refuse)
    assert made == []


