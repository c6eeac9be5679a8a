"""A program's gouging cut is cut back to its last verified point and the rest listed."""

from __future__ import annotations

import numpy as np

import cadcnc
from cadcnc.ops.path.pair_path import intersection_path
from cadcnc.program.linking import linked
from cadcnc.program.program import CutSegment, Program
from cadcnc.verification import gouge_gate
from cadcnc.verification.cut_back import CUT_BACK, GOUGE, cut_back
from helpers.fixtures import FIXTURES


def test_a_cut_running_into_a_wall_is_cut_back_where_the_ball_reaches_it():
    """stretch_pocket: the floor-wall corner's stretch ends where the ball touches the end
    wall at x = 32 (closed form, fixtures/stretch_fixtures.json). A path run on to x = 34
    without the guard cuts that wall; cut back, it ends within a step of x = 32."""
    part = cadcnc.load_step(FIXTURES / "stretch_pocket.step")
    tp = intersection_path(part.face(11), part.face(8), radius=3.0, feed=1500.0,
                                  period=0.004, start=(10.0, 8.0, 11.0), end=(34.0, 8.0, 11.0))
    assert not gouge_gate(tp, part).ok
    prog = Program(tp.job, linked([CutSegment(tp), CutSegment(tp)], 60.0), [])
    back = cut_back(prog, part, 60.0)
    assert len(back.cuts) == 2 and [s.reason for s in back.skipped] == [GOUGE, GOUGE]
    cut = back.cuts[0]
    assert cut.path.stop_reason == CUT_BACK and cut.at_limit and back.complete
    assert 32.0 - 0.1 - 1e-6 <= cut.points[-1][0] <= 32.0 + 1e-6
    np.testing.assert_array_equal(cut.points, tp.points[:len(cut.points)])
    assert gouge_gate(cut.path, part).ok
    assert "cut back after" in back.skipped[0].detail


def test_a_clear_program_is_left_as_it_is():
    part = cadcnc.load_step(FIXTURES / "stretch_pocket.step")
    tp = intersection_path(part.face(11), part.face(8), radius=3.0, feed=1500.0,
                                  period=0.004, start=(10.0, 8.0, 11.0), end=(30.0, 8.0, 11.0))
    prog = Program(tp.job, linked([CutSegment(tp)], 60.0), [])
    assert cut_back(prog, part, 60.0) is prog


def _pocket_program(end_x: float):
    """stretch_pocket's floor-wall corner from x = 10 to ``end_x`` (past 32 it gouges the
    end wall), as a program of one cut with the pencil's cut-back gap."""
    from dataclasses import replace

    from cadcnc.core.job import Pencil

    part = cadcnc.load_step(FIXTURES / "stretch_pocket.step")
    tp = intersection_path(part.face(11), part.face(8), radius=3.0, feed=1500.0,
                           period=0.004, start=(10.0, 8.0, 11.0), end=(end_x, 8.0, 11.0))
    job = replace(tp.job, operation=Pencil())
    return part, job, Program(job, linked([CutSegment(tp)], 60.0), [])


def test_the_pipeline_gates_a_clear_program_once(monkeypatch):
    """A program whose written moves all pass is not cut back: the cut-back's own gate
    is not run, and the program and verdict are those of the gate alone; a gouging one
    is cut back and gated again, its verdict passing."""
    from cadcnc.pipeline import operate

    settled = []
    real = operate.settle
    monkeypatch.setattr(operate, "settle", lambda *a, **k: settled.append(1) or real(*a, **k))
    part, job, prog = _pocket_program(30.0)
    out, verdict = operate.settled_and_judged(prog, part, job, "pencil", "pencil",
                                              operate.Settings())
    assert out is prog and verdict.gate.ok and verdict.code == 0 and not settled
    part, job, prog = _pocket_program(34.0)
    out, verdict = operate.settled_and_judged(prog, part, job, "pencil", "pencil",
                                              operate.Settings())
    assert settled == [1] and out is not prog and verdict.gate.ok
    assert out.cuts[0].points[-1][0] <= 32.0 + 1e-6 and out.skipped[0].reason == GOUGE
