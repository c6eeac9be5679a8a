"""A stream made a block of periods at a time: the targets, the positions, the rows of
each segment and the limits' peaks are the same numbers as the whole arrays give, and a
long stream's positions live in a scratch file, not in memory."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.controller import Machine, feed_plan, stream_program
from cadcnc.controller import stream as stream_module
from cadcnc.controller.stream import _over, _peaks, _segment_rows
from cadcnc.core import scratch
from cadcnc.ops.path.pair_path import pair_job
from cadcnc.ops.path.pair_program import program_for_job
from cadcnc.ops.stream_steppers import stepper_factory
from helpers.fixtures import FIXTURES


def _whole_targets(plan) -> tuple[np.ndarray, np.ndarray]:
    """The targets as one array each (the specification the blocks must match)."""
    n, period, starts = plan.periods, plan.machine.period, plan.starts
    piece, s = np.empty(n + 1, dtype=np.int64), np.empty(n + 1)
    times = np.arange(n + 1) * period
    run_of = np.searchsorted(starts[1:-1], times, side="right")
    for j, run in enumerate(plan.runs):
        sel = np.flatnonzero(run_of == j)
        if not len(sel):
            continue
        at = plan.profiles[j].position(times[sel] - starts[j])
        k = np.clip(np.searchsorted(run.offsets, at, side="right") - 1, 0,
                    len(run.pieces) - 1)
        piece[sel] = run.first + k
        s[sel] = np.clip(at - run.offsets[k], 0.0, np.diff(run.offsets)[k])
    return piece, s


def test_segment_rows_are_the_search_over_every_rows_segment():
    """Each segment's first row from the pieces' first rows equals the search over the
    segment of every row (row 0 counted in segment 0)."""
    rng = np.random.default_rng(7)
    for _ in range(300):
        pieces = int(rng.integers(1, 12))
        rows_per_piece = rng.integers(0, 4, pieces)
        starts = np.r_[0, np.cumsum(rows_per_piece)]
        segments = np.sort(rng.integers(0, 6, pieces))
        count = int(segments[-1]) + 1 + int(rng.integers(0, 2))
        seg_of_row = segments[np.repeat(np.arange(pieces), rows_per_piece)]
        if not len(seg_of_row):
            continue
        seg_of_row[0] = 0
        want = np.searchsorted(seg_of_row, np.arange(count + 1), side="left")
        assert np.array_equal(_segment_rows(starts, list(segments), count), want)


def test_peaks_are_the_whole_arrays_differences(monkeypatch):
    """The blockwise peaks (blocks of 7 rows) are the largest |finite differences| of the
    whole array, at the first row reaching them; the shares and the refusal's figures are
    those of the whole arrays over the limits, bit for bit."""
    monkeypatch.setattr(stream_module, "CHUNK", 7)
    machine = Machine.default()
    x = np.cumsum(np.random.default_rng(3).normal(size=(200, 3)) * 1e-3, axis=0)
    peak, where = _peaks(x)
    over = _over(x, machine)
    for k, lim in enumerate((machine.max_velocity, machine.max_acceleration,
                             machine.max_jerk), start=1):
        d = np.abs(np.diff(x, k, axis=0))
        assert np.array_equal(peak[k - 1], d.max(axis=0))
        assert np.array_equal(where[k - 1], d.argmax(axis=0) + k)
        share = d / (machine.period ** k * np.asarray(lim))
        row, axis = np.unravel_index(int(np.argmax(share)), share.shape)
        assert over[k - 1] == (float(share[row, axis]), int(row) + k, int(axis))


def test_the_first_axis_to_reach_a_shared_peak_is_named():
    """Two axes at the same share: the refusal names the one that reached it first (a Y
    jump at row 5, then the same X jump at row 12), as the whole array's search does."""
    machine = Machine.default()
    assert machine.max_velocity[0] == machine.max_velocity[1]
    x = np.zeros((20, 3))
    x[5:, 1] += 1e-3
    x[12:, 0] += 1e-3
    share, row, axis = _over(x, machine)[0]
    assert (row, axis) == (5, 1)


def test_positions_that_are_not_numbers_are_left_to_the_check():
    """A block with a NaN adds nothing to the peaks (the stream's check names it)."""
    x = np.zeros((10, 3))
    x[4, 0] = np.nan
    x[6:, 1] = 1.0
    peak, _ = _peaks(x)
    assert not peak.any()


@pytest.mark.slow
def test_a_stream_in_small_blocks_and_a_scratch_file_is_the_same_stream(monkeypatch):
    """The corner's stream made 97 periods at a time, its positions in a scratch file:
    the targets equal the whole arrays', and the positions, the pieces' rows, the
    segments' moves and the summary equal the stream made in memory, bit for bit."""
    part = cadcnc.load_step(FIXTURES / "bspline_boss.step")
    _, _, job = pair_job(part.face(4), part.face(5), radius=3.0, feed=1500.0, period=0.004)
    program = program_for_job(part, job)
    machine = Machine.default()
    whole = stream_program(program, machine, stepper_factory(part))
    assert not isinstance(whole.positions, np.memmap)

    piece, s = _whole_targets(whole.plan)
    blocks = list(whole.plan.blocks(size=97))
    assert max(len(b) for _, _, b in blocks) <= 97
    assert np.array_equal(np.concatenate([np.full(len(b), j) for j, _, b in blocks]), piece)
    assert np.array_equal(np.concatenate([b for _, _, b in blocks]), s)
    firsts = np.cumsum([0] + [len(b) for _, _, b in blocks[:-1]])
    assert [r for _, r, _ in blocks] == firsts.tolist()

    monkeypatch.setattr(feed_plan, "BLOCK_ROWS", 97)
    monkeypatch.setattr(scratch, "IN_MEMORY_ROWS", 100)
    small = stream_program(program, machine, stepper_factory(part))
    assert isinstance(small.positions, np.memmap)
    assert np.array_equal(small.positions, whole.positions)
    assert np.array_equal(small.starts, whole.starts)
    assert np.array_equal(small.rows, piece)
    assert (small.kernel_cuts, small.hermite_cuts) == (whole.kernel_cuts, whole.hermite_cuts)
    for a, b in zip(small.segment_moves(program), whole.segment_moves(program)):
        assert np.array_equal(a, b)
    assert small.summary() == whole.summary()


def test_rows_out_of_piece_order_are_refused(monkeypatch):
    """A plan whose rows went back to an earlier piece refuses (no mixed pieces)."""
    machine = Machine.default()
    pieces = [_Line((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)), _Line((1.0, 0.0, 0.0), (2.0, 0.0, 0.0))]

    class _Plan:
        def checked_periods(self, max_periods):
            return 3

        def blocks(self, max_periods):
            yield 1, 0, np.zeros(2)
            yield 0, 2, np.zeros(2)

    monkeypatch.setattr(stream_module, "plan_feed", lambda *a: _Plan())
    with pytest.raises(ValueError, match="not in the order"):
        stream_module._stream(None, machine, pieces, None, True, np.ones(3), 10, None)


class _Line:
    """A link's straight piece (what ``_stream`` reads of a piece)."""

    cut = None

    def __init__(self, a, b):
        self.points = np.array([a, b], dtype=float)
        self.length = float(np.linalg.norm(self.points[1] - self.points[0]))


def test_a_replan_lets_the_last_positions_go_first(monkeypatch):
    """Each replan's positions are made after the last ones are let go: one scratch file
    of a long stream at a time, not two."""
    import weakref

    from cadcnc.controller.feed_plan import PlanError

    made, alive = [], []

    class _Made:
        positions = np.zeros((5, 3))
        plan = feed_plan.FeedPlan([], [], [], Machine.default())   # nothing measured

    def fake_stream(*args):
        alive.append(sum(ref() is not None for ref in made))
        out = _Made()
        made.append(weakref.ref(out))
        return out

    monkeypatch.setattr(stream_module, "stream_pieces", lambda *a: [])
    monkeypatch.setattr(stream_module, "_stream", fake_stream)
    monkeypatch.setattr(stream_module, "_over", lambda positions, machine: [(1.01, 1, 0)] * 3)
    with pytest.raises(PlanError):
        stream_program(None, Machine.default())
    assert alive == [0] * (stream_module.REPLANS + 1)


def test_a_measured_plan_over_a_limit_is_planned_again_with_its_limits_held(monkeypatch):
    """A first plan that took some run's limits where they are (``plan.measured``) and
    breaks a limit is planned again with every limit held over the reach, before any
    limit is lowered; then REPLANS lowered limits at most, then refused."""
    from types import SimpleNamespace

    from cadcnc.controller.feed_plan import PlanError

    asked = []

    def fake_stream(*args):
        asked.append((args[-1], tuple(args[5])))   # measured, derate
        return SimpleNamespace(positions=np.zeros((5, 3)),
                               plan=SimpleNamespace(measured=args[-1]))

    monkeypatch.setattr(stream_module, "stream_pieces", lambda *a: [])
    monkeypatch.setattr(stream_module, "_stream", fake_stream)
    monkeypatch.setattr(stream_module, "_over", lambda positions, machine: [(1.01, 1, 0)] * 3)
    with pytest.raises(PlanError):
        stream_program(None, Machine.default())
    assert [m for m, _ in asked] == [True] + [False] * (stream_module.REPLANS + 1)
    assert asked[0][1] == asked[1][1] == (1.0, 1.0, 1.0) and asked[2][1] < (1.0, 1.0, 1.0)


def test_a_cut_shorter_than_short_cut_is_positioned_from_its_points():
    """A cut under SHORT_CUT (r0901_ec's pencil at R 2 has a 3.8 µm one, which the kernel
    re-run stepped past) takes its positions from its points: no stepper is built, and
    its rows at its points' arc lengths are those points (its ends exactly)."""
    from cadcnc.controller import cut_rows
    from cadcnc.controller.pieces import Piece

    p = np.linspace([0.0, 0.0, 0.0], [-8.1e-7, 1.02e-6, 3.83e-3], 5)
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
    piece = Piece(p, s, 166.7, 0, cut=0, kappa=np.zeros(5))
    assert piece.length < cut_rows.SHORT_CUT

    def no_stepper(*args):
        raise AssertionError("a stepper was built for a short cut")

    counts = {"kernel": 0, "hermite": 0}
    rows = cut_rows.piece_rows(None, Machine.default(), piece, no_stepper, counts)
    assert counts == {"kernel": 0, "hermite": 1}
    assert np.abs(rows(s) - p).max() < 1e-15
