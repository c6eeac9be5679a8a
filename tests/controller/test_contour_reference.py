"""The true-contour-error reference (benchmarks/controller/contour.py) checked on its own,
then the stream's true contour error on the three programs at 10 000 mm/min (issue 35)."""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.testing.contour_reference import Arc, Line, Offsets, PathReference, fit_arc, fit_line

UM = 1e-3   # mm


def _arc_points(n=200, r=9.0, span=1.3):
    """Points on an arc of radius r in a tilted plane, and its centre, normal, e1."""
    c = np.array([1.0, -2.0, 3.0])
    n_ = np.array([0.2, -0.3, 0.9]) / np.linalg.norm([0.2, -0.3, 0.9])
    e1 = np.cross(n_, [1.0, 0, 0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n_, e1)
    t = np.linspace(0, span, n)
    return c + r * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2), c, n_, e1


def test_line_and_arc_closed_forms():
    pts, c, n, _ = _arc_points()
    arc = fit_arc(pts)
    assert isinstance(arc, Arc) and abs(arc.r - 9.0) < 1e-12
    assert np.linalg.norm(arc.c - c) < 1e-11 and abs(arc.span - 1.3) < 1e-12
    assert fit_line(pts) is None
    assert arc.distance(pts).max() < 1e-12
    radial = (pts - c) / 9.0
    for off in (pts + UM * radial, pts - UM * radial, pts + UM * n):
        assert np.allclose(arc.distance(off), UM, rtol=0, atol=1e-12)
    # past the arc's end: the distance to the end point, not to the full circle
    beyond = c + 9.0 * (np.cos(2.0) * arc.e1 + np.sin(2.0) * arc.e2)
    assert arc.distance(beyond)[0] == pytest.approx(np.linalg.norm(beyond - pts[-1]))
    # an ellipse is no arc; a bent line is no line
    squashed = pts.copy()
    squashed[:, 2] += 1e-6 * np.sin(np.linspace(0, 3, len(pts)))
    assert fit_arc(squashed) is None
    line = fit_line(np.linspace([0, 0, 0], [3, 4, 0], 50))
    assert isinstance(line, Line)
    bent = np.linspace([0, 0, 0], [3, 4, 0], 50)
    bent[25, 2] = 1e-8
    assert fit_line(bent) is None
    q = np.linspace([0, 0, 0], [3, 4, 0], 50) + UM * np.array([0, 0, 1])
    assert np.allclose(line.distance(q), UM, atol=1e-15)
    assert line.distance(np.array([6.0, 8, 0]))[0] == pytest.approx(5.0)


@pytest.fixture(scope="module")
def streams():
    from benchmarks.controller.stream_cost import programs
    from cadcnc.controller import Machine, stream_program
    from cadcnc.ops.stream_steppers import stepper_factory

    out = {}
    for name, part, program in programs():
        s = stream_program(program, Machine.default(), stepper_factory(part), feed=10_000.0)
        out[name.split()[0]] = (program, s, PathReference(s.plan.pieces, program, part))
    return out


@pytest.mark.slow
def test_reference_on_the_programs_paths(streams):
    """Points known on each cut's path give ~0; moved 1 µm off it, 1 µm."""
    kinds = {tag: ref.kinds() for tag, (_, _, ref) in streams.items()}
    assert kinds["pencil"] == {"line": 4}
    assert kinds["finish"] == {"line": 8, "arc": 3}
    assert kinds["corner"] == {"line": 3, "offsets": 1}
    for tag, (program, s, ref) in streams.items():
        for piece, r in zip(s.plan.pieces, ref.refs):
            if piece.cut is None:
                continue
            pts = piece.points
            if isinstance(r, Offsets):
                # the kernel's own points are off the offset surfaces by its point error
                kernel = r.distance(pts)
                assert 1e-7 < kernel.max() < 2e-5, kernel.max()
                on = np.array([r.on_path(p) for p in pts[3:-3:25]])
                assert r.distance(on).max() < 1e-9
                for face in range(2):
                    normal = []
                    for q in on:
                        d, foot = r.feet(q)[face]
                        normal.append((q - foot) / d)
                    off = r.distance(on + UM * np.array(normal))
                    assert np.allclose(off, UM, rtol=0, atol=1e-9), (face, off)
                continue
            assert r.distance(pts).max() < 1e-12
            if isinstance(r, Arc):   # off in the arc's plane (radially) and across it
                radial = (pts - r.c) - np.outer((pts - r.c) @ r.n, r.n)
                sides = [radial / np.linalg.norm(radial, axis=1)[:, None], r.n[None]]
            else:
                d = (r.b - r.a) / np.linalg.norm(r.b - r.a)
                side = np.cross(d, [0.3, 0.5, 0.8])
                sides = [(side / np.linalg.norm(side))[None]]
            for side in sides:
                got = r.distance(pts[1:-1] + UM * side[1:-1] if len(side) > 1
                                 else pts[1:-1] + UM * side)
                assert np.allclose(got, UM, rtol=0, atol=2e-9), (tag, r.kind, got.min(), got.max())


@pytest.mark.slow
def test_stream_true_contour_error_within_a_tenth_of_a_micron(streams):
    """The issue's target: every row within 0.1 µm of its own piece's exact path."""
    for tag, (program, s, ref) in streams.items():
        err = ref.stream_error(s.positions, s.rows)
        assert len(err) == len(s.positions) > 1000
        assert err.max() <= 0.1 * UM, (tag, err.max())
        # rows are measured against their own piece: the nearest piece gives no more
        assert ref.distance(s.positions[::7]).max() <= err.max() + 1e-15


@pytest.mark.slow
def test_a_finishing_pass_on_a_free_form_face_is_measured_on_its_offset_and_plane():
    """finish_slab's B-spline face 5, raster R 3: each pass is a Guided reference (the
    face's offset by OCCT, the plane fitted to the pass); the kernel's points lie on it,
    a point moved 1 µm off the plane is 1 µm off, and Newton's point is on it."""
    import cadcnc
    from cadcnc.controller import Machine
    from cadcnc.controller.pieces import pieces_of
    from cadcnc.ops.finish.shortcut import finish
    from cadcnc.testing.contour_reference import Guided, piece_reference
    from helpers.fixtures import FIXTURES

    part = cadcnc.load_step(FIXTURES / "finish_slab.step")
    program = finish(part, [5], radius=3.0, stepover=4.0)
    pieces = [pc for pc in pieces_of(program, Machine.default(), 10_000.0)
              if pc.cut is not None][:2]
    for pc in pieces:
        ref = piece_reference(pc, program, part)
        assert isinstance(ref, Guided)
        pts = np.asarray(pc.points)[::7]
        assert ref.distance(pts).max() < 1e-9
        assert np.allclose(ref.distance(pts + UM * ref.n), UM, rtol=0, atol=1e-9)
        q = ref.on_path(pts[len(pts) // 2] + np.array([2e-3, -1e-3, 3e-3]))
        assert ref.distance(q)[0] < 1e-12


def test_an_open_loop_s_start_is_not_measured_past_its_other_end():
    """A waterline loop that stops short of closing (300° here): its first point lies
    ahead of its last along the last tangent, yet is on the path (it was measured at
    the gap between the ends, 40 mm on the slab's waterline); a point past an end still
    counts its distance to that end."""
    import cadquery as cq

    top = cq.Workplane().box(100, 100, 10).faces(">Z").val().wrapped   # z = 5
    R = 3.0
    t = np.radians(np.linspace(0.0, 300.0, 301))
    pts = np.c_[10 * np.cos(t), 10 * np.sin(t), np.full_like(t, 5.0 + R)]
    ref = Offsets([top], (R,), pts)
    assert ref.distance(pts[[0, 150, -1]]).max() < 1e-9
    tangent = (pts[-1] - pts[-2]) / np.linalg.norm(pts[-1] - pts[-2])
    beyond = pts[-1] + 0.5 * tangent
    assert abs(ref.distance(beyond)[0] - 0.5) < 1e-9
