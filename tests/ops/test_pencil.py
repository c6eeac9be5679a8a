"""Pencil: every corner of a part in one program, chained, linked, verified."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.io.program_cq import to_cq
from cadcnc.ops.path.pair_program import climb_measure
from cadcnc.verification import gouge_gate
from helpers.fixtures import FIXTURES, load_fixture
from helpers.programs import pencil_run

_programs: dict = {}


def program_of(name: str, **kw):
    key = (name, tuple(sorted(kw.items())))
    if key not in _programs:
        part = load_fixture(name) if name == "pocket" else cadcnc.load_step(
            FIXTURES / f"{name}.step")
        _programs[key] = (part, pencil_run(part, radius=3.0, **kw))
    return _programs[key]


def test_pocket_floor_corners_are_one_loop_without_lift():
    """The pocket's eight floor-to-wall corners (walls and wall fillets larger than the
    ball) come out as one closed loop, each cut starting where the last ended (a link
    between them only where they meet a hair apart), climb."""
    part, prog = program_of("pocket")
    floor = [s for s in prog.segments if s.kind == "cut" and 17 in s.path.faces]
    assert len(floor) == 8
    k0 = next(k for k, s in enumerate(prog.segments) if s is floor[0])
    k1 = next(k for k, s in enumerate(prog.segments) if s is floor[-1])
    run = prog.segments[k0:k1 + 1]
    assert [s for s in run if s.kind == "cut"] == floor
    for a, b in zip(run, run[1:]):
        np.testing.assert_allclose(a.points[-1], b.points[0], atol=1e-3)
    lifts = [s for s in run if s.kind == "link"]
    assert all(len(s.points) == 2 and not s.rapid.any() and s.length < 1e-3 for s in lifts)
    np.testing.assert_allclose(floor[-1].points[-1], floor[0].points[0], atol=1e-3)
    assert all(climb_measure(c.path) > 0 for c in floor)
    assert prog.complete


def test_conventional_runs_the_other_way():
    _, climb = program_of("pocket")
    _, conv = program_of("pocket", side="conventional")
    floor = [c for c in conv.cuts if 17 in c.path.faces]
    assert len(floor) == 8 and all(climb_measure(c.path) < 0 for c in floor)
    assert conv.cut_length == pytest.approx(climb.cut_length, abs=1e-6)


def test_skipped_corners_carry_their_reason():
    _, prog = program_of("fillet_pocket")
    reasons = {s.reason for s in prog.skipped}
    assert "blend_rolls" in reasons            # the r 5 wall fillets: the ball rolls on them
    assert all(s.detail for s in prog.skipped)
    assert len(prog.cuts) >= 4


@pytest.mark.parametrize("name", ["pocket", "step_slot"])
def test_every_move_clears_the_part(name):
    """Every cut point touches its faces and no move, links included, cuts the part."""
    part, prog = program_of(name)
    moves = prog.all_moves()
    for cut in prog.cuts:
        gate = gouge_gate(cut.path, part, moves=moves if cut is prog.cuts[0] else None)
        assert gate.ok, gate.message
    assert len(prog.links) >= 2


def test_side_is_checked():
    with pytest.raises(cadcnc.InputError, match="side"):
        pencil_run(load_fixture("pocket"), radius=3.0, side="up")


def test_cadquery_example_runs_as_script_and_under_cq_editor(capsys):
    """docs/examples/pencil_example.py: a Workplane in, wires out through the cut points."""
    import runpy

    from helpers.fixtures import ROOT

    example = str(ROOT / "docs" / "examples" / "pencil_example.py")
    shown = {}
    ns = runpy.run_path(example, init_globals={
        "show_object": lambda obj, name="", options=None: shown.__setitem__(name, obj)})
    prog = ns["program"]
    assert set(shown) == {"part", "cuts", "links"} and prog.complete
    # the round pocket r 8 (ball centres on r 6, once around) and the step, 30 mm across
    assert sorted(c.length for c in prog.cuts) == pytest.approx([30.0, 12 * np.pi], abs=0.01)
    wires = to_cq(prog, links=False)
    assert len(wires) == len(prog.cuts)
    for w, cut in zip(wires, prog.cuts):
        ends = np.array([w.startPoint().toTuple(), w.endPoint().toTuple()])
        np.testing.assert_allclose(ends, cut.points[[0, -1]], atol=1e-3)
        assert w.Length() == pytest.approx(cut.length, abs=1e-3)
    assert len(shown["links"].Wires()) == len(to_cq(prog, cuts=False))
    runpy.run_path(example, run_name="__main__")  # as a plain script: prints the summary
    assert "pencil R 2:" in capsys.readouterr().out


def test_pencil_takes_a_cadquery_shape():
    import cadquery as cq

    step = cq.Workplane("XY").box(20, 10, 10).faces(">Z").workplane().center(5, 0).rect(
        10, 10).cutBlind(-4)  # a step: one concave edge, 10 mm long
    part_prog = pencil_run(cadcnc.Part.from_cadquery(step.val()), radius=2.0)
    shape_prog = pencil_run(step.val(), radius=2.0)
    work_prog = pencil_run(step, radius=2.0)
    assert len(part_prog.cuts) == 1 and part_prog.cut_length == pytest.approx(10, abs=0.1)
    for other in (shape_prog, work_prog):
        np.testing.assert_array_equal(other.cuts[0].points, part_prog.cuts[0].points)


def test_blend_corners_are_cut_by_stretches_between_their_limits():
    """fillet_pocket (fixtures/build_pencil_fixtures.py: pocket x -25..25, y -18..18,
    floor z 18, floor fillet r 1.5, vertical fillets r 2 at x = 25 and r 5 at x = -25), R'
    3: across the floor fillet the ball sits R' from wall and floor (z 21, 3 mm inside the
    wall); each wall's corner runs from where the r 5 fillet begins (x -20) to where the
    ball touches the x = 25 wall (x 22), the x = 25 wall's between the y = +-18 walls
    (y +-15); across the r 2 vertical fillets the ball runs from the floor (z 21) to the
    top (z 30). Before stretches, the floor blends next to the r 2 fillets were skipped
    (their first seed blocked by the next wall)."""
    _, prog = program_of("fillet_pocket")
    ends = {tuple(sorted(c.path.faces)): c.points[[0, -1]] for c in prog.cuts}
    want = {(10, 23): [(-20, -15, 21), (22, -15, 21)], (14, 23): [(-20, 15, 21), (22, 15, 21)],
            (12, 23): [(22, -15, 21), (22, 15, 21)], (10, 12): [(22, -15, 21), (22, -15, 30)],
            (12, 14): [(22, 15, 21), (22, 15, 30)], (8, 23): [(-22, -13, 21), (-22, 13, 21)]}
    for pair, pts in want.items():
        got = ends[pair]
        if np.linalg.norm(got[0] - pts[0]) > np.linalg.norm(got[0] - pts[1]):
            got = got[::-1]  # the side rule may run it either way
        np.testing.assert_allclose(got, np.array(pts, float), atol=1e-3, err_msg=str(pair))
    assert not any(s.faces in ((10, 23), (12, 23)) for s in prog.skipped)
    assert prog.complete


def test_a_hole_of_the_balls_radius_is_cut_by_a_plunge():
    """narrow_slot's flat-bottom hole r 2 with a 2 mm ball: R' k = 1 is a tie, not a
    face tighter than the ball; its corner is one position (10, 10, 17), a point cut,
    and the program (links included) clears the part."""
    part = cadcnc.load_step(FIXTURES / "narrow_slot.step")
    prog = pencil_run(part, radius=2.0)
    (point,) = [c for c in prog.cuts if len(c.points) == 1]
    np.testing.assert_allclose(point.points[0], (10.0, 10.0, 17.0), atol=1e-6)
    assert point.path.faces == (11, 12) and prog.complete and not prog.skipped
    gate = gouge_gate(point.path, part, moves=prog.all_moves())
    assert gate.ok, gate.message


def test_the_guard_keeps_own_face_edges_within_the_written_programs_allowance():
    """A cut may end where the ball reaches its own face's edge (a B-spline face whose edge
    lies off its surface by the file's tolerance). The gate of the written program allows
    the gouge limit less G64 P (blend_for) and the G-code's rounding (tolerance / 10, the
    rule of digits_for): every operation's guard (pencil's, path's) must stop the ball inside that, with room for the
    chords between points; third faces keep the 1 nm rule."""
    from cadcnc.core.job import Job, PairPath, Tool
    from cadcnc.guard import guard_for
    from cadcnc.io.gcode import DEFAULT_TOLERANCE, blend_for, digits_for

    part = load_fixture("pocket")
    job = Job(Tool(3.0, 0.0), 1500.0, 0.004, PairPath(faces=(9, 12), edge=0))
    tol = job.tolerances
    guard = guard_for(part, (9, 12), job)
    gouge = tol.gouge
    rounding = np.sqrt(3) / 2 * 10.0 ** -digits_for(DEFAULT_TOLERANCE)
    room = gouge - blend_for(gouge) - rounding            # what the written moves may use
    intrusion = guard.offset - guard.own_threshold        # what the guard lets the ball do
    assert 0.0 < intrusion <= room - 0.05 * gouge, (intrusion, room)
    assert guard.threshold == pytest.approx(guard.offset - tol.hit, abs=1e-15)
