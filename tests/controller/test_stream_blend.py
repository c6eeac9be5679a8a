"""``--blend``: a link's corners rounded in the stream, judged from outside: finite
differences of the positions against every limit, the cycle time against exact stops,
the distance of every link row from the link's own polyline, the cut rows on the
unblended cut's path, and the gate refusing a rounded link that cuts a wall's edge (the
stream then falls back to the link's exact corners). No code shared with the planner."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import cadcnc
from cadcnc.controller import Machine, stream_program
from cadcnc.core.errors import EXIT_OK
from cadcnc.ops.stream_steppers import stepper_factory
from cadcnc.pipeline.streaming import stream_to
from cadcnc.program.program import LinkSegment
from cadcnc.verification import gate_program
from helpers.fixtures import FIXTURES

SLACK = 1e-6
FAST = 10_000.0   # mm/min
BLEND = 20.0      # mm
AGILE = Machine(0.001, (20.0,) * 3, (2000.0,) * 3, (200_000.0,) * 3,
                "slow axes, quick acceleration: a corner passes at full speed")


@pytest.fixture(scope="module")
def tall():
    """The pencil program of pocket.step with its links at Z 80 (legs of 50 mm and more),
    streamed on the default machine with exact corners and with ``BLEND``."""
    part = cadcnc.load_step(FIXTURES / "pocket.step")
    prog = cadcnc.run(part, cadcnc.Job(cadcnc.Tool(3.0), 1500.0, 0.004, cadcnc.Pencil(),
                                       source=part.source, clearance=80.0))
    m = Machine.default()
    exact = stream_program(prog, m, stepper_factory(part), feed=FAST)
    blended = stream_program(prog, m, stepper_factory(part), feed=FAST, blend=BLEND)
    return part, prog, m, exact, blended


def _shares(x: np.ndarray, m: Machine) -> np.ndarray:
    """(3,) the largest |v|, |a|, |j| of the positions over the limits (any axis)."""
    return np.array([(np.abs(np.diff(x, k, axis=0)) / m.period ** k / np.asarray(lim)).max()
                     for k, lim in ((1, m.max_velocity), (2, m.max_acceleration),
                                    (3, m.max_jerk))])


def _to_polyline(x: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """(n,) the distance of each point (n, 3) to the polyline (m, 3)."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    t = np.einsum("nmk,mk->nm", x[:, None] - a[None], ab) / np.maximum(
        np.einsum("mk,mk->m", ab, ab), 1e-300)
    near = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    return np.linalg.norm(x[:, None] - near, axis=2).min(axis=1)


def _segment_rows(stream, k: int) -> np.ndarray:
    seg = np.array([p.segment for p in stream.plan.pieces])[stream.rows]
    return stream.positions[seg == k]


def test_the_blended_stream_keeps_every_limit(tall):
    _, _, m, _, blended = tall
    assert blended.rounded   # something was rounded
    assert (_shares(blended.positions, m) <= 1.0 + SLACK).all()


def test_the_blend_shortens_the_cycle(tall):
    _, _, _, exact, blended = tall
    assert blended.cycle_time < 0.98 * exact.cycle_time   # measured 13.14 s vs 13.83 s


def test_link_rows_stay_within_the_blend_of_the_link(tall):
    _, prog, _, _, blended = tall
    for k in blended.rounded:
        rows = _segment_rows(blended, k)
        far = _to_polyline(rows, prog.segments[k].points).max()
        assert far <= BLEND + 1e-9
        assert far > 0.1   # the corner was really cut


def test_cut_rows_lie_on_the_unblended_cuts_path(tall):
    """The blended stream reaches a cut at another phase of the servo period, so its rows
    fall between the exact stream's: within the sag of the exact rows' chords (h² k / 8,
    k the cut's largest curvature) plus 1e-9 mm of them, led and ended by the cut's ends."""
    _, prog, _, exact, blended = tall
    pieces = {p.segment: p for p in exact.plan.pieces if p.cut is not None}
    for k, seg in enumerate(prog.segments):
        if seg.kind != "cut":
            continue
        rows = _segment_rows(blended, k)
        ref = np.vstack([seg.points[:1], _segment_rows(exact, k), seg.points[-1:]])
        h = np.linalg.norm(np.diff(ref, axis=0), axis=1).max()
        sag = h * h * float(pieces[k].kappa.max()) / 8.0
        assert _to_polyline(rows, ref).max() <= sag + 1e-9


def test_blend_zero_is_the_exact_stream(tall):
    part, prog, m, exact, _ = tall
    again = stream_program(prog, m, stepper_factory(part), feed=FAST, blend=0.0)
    assert again.positions.tobytes() == exact.positions.tobytes()
    assert not again.rounded


def test_the_gate_refuses_a_rounded_corner_over_a_wall_and_the_stream_falls_back():
    """The link into the pocket crosses the rim 4 mm above it (the ball 1 mm clear) and
    drops beside the wall: rounded within 20 mm (5.6 mm: 0.4 of the 14 mm drop) its
    corner passes 1 to 2 mm from the rim's edge, inside the ball."""
    part = cadcnc.load_step(FIXTURES / "pocket.step")
    prog = cadcnc.run(part, cadcnc.Job(cadcnc.Tool(3.0), 1500.0, 0.004, cadcnc.Pencil(),
                                       source=part.source, clearance=80.0))
    k = 2
    start, end = prog.segments[k].points[0], prog.segments[k].points[-1]
    over = end[2] + 16.0   # the rim's top (Z 30) + the radius + 1 mm
    pts = [start, (*start[:2], 80.0), (-80.0, end[1], 80.0), (-80.0, end[1], over),
           (*end[:2], over), (*end[:2], end[2] + 2.0), end]
    link = LinkSegment(np.array(pts, float), [True, True, True, True, True, False])
    prog = replace(prog, segments=[*prog.segments[:k], link, *prog.segments[k + 1:]])
    blended = stream_program(prog, AGILE, stepper_factory(part), feed=FAST, blend=BLEND)
    assert k in blended.rounded
    gate = gate_program(prog, part, moves=blended.segment_moves(prog))
    assert not gate.ok and gate.link_failed[1]
    run = stream_to(prog, part, AGILE, [], feed=FAST, blend=BLEND)
    assert run.code == EXIT_OK
    assert k not in run.stream.rounded
    exact = stream_program(prog, AGILE, stepper_factory(part), feed=FAST, blend=0.0)
    np.testing.assert_array_equal(_segment_rows(run.stream, k), _segment_rows(exact, k))
