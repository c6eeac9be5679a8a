"""A cut whose recorded start lies a few nm off the kernel's exact path (a waterline loop
of bug28414's toroidal part starts 13-24 nm off it): the kernel's first step corrects
across the path in one period, a jolt of 20 nm / Ts³. The stream settles the start first
and gives the move out over the cut's first mm. Here the corner's cut starts 20 nm off
its path (the link into it ends there too, as a program records it); its stream, planned
once, is checked by finite differences: within every limit with the settling, several
times the jerk limit without."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import cadcnc
from cadcnc.controller import Machine, cut_rows
from cadcnc.controller import stream as st
from cadcnc.ops.path.pair_path import pair_job
from cadcnc.ops.path.pair_program import program_for_job
from cadcnc.ops.stream_steppers import stepper_factory
from cadcnc.program.program import CutSegment, LinkSegment
from helpers.fixtures import FIXTURES

OFF = 2e-5   # mm across the path


@pytest.fixture(scope="module")
def corner():
    """The corner program with its cut's first point (and the link's last) moved OFF mm
    across the path."""
    part = cadcnc.load_step(FIXTURES / "bspline_boss.step")
    _, _, job = pair_job(part.face(4), part.face(5), radius=3.0, feed=1500.0, period=0.004)
    program = program_for_job(part, job)
    k = next(i for i, seg in enumerate(program.segments) if isinstance(seg, CutSegment))
    cut, link = program.segments[k], program.segments[k - 1]
    assert isinstance(link, LinkSegment)
    p = cut.path.points
    t = (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])
    across = np.cross(t, [0.0, 0.0, 1.0])
    start = p[0] + OFF * across / np.linalg.norm(across)
    points = p.copy()
    points[0] = start
    ends = link.points.copy()
    ends[-1] = start
    segments = list(program.segments)
    segments[k] = dataclasses.replace(cut, path=dataclasses.replace(cut.path, points=points))
    segments[k - 1] = dataclasses.replace(link, points=ends)
    return part, dataclasses.replace(program, segments=segments)


def _jerk_share(corner) -> float:
    part, program = corner
    machine = Machine.default()
    pieces = st.stream_pieces(program, machine, 3000.0)
    stream = st._stream(program, machine, pieces, stepper_factory(part), True, np.ones(3),
                        st.MAX_PERIODS, None, measured=False)
    x = stream.positions
    jerk = np.abs(np.diff(x, 3, axis=0)) / machine.period ** 3
    return float(np.max(jerk / np.asarray(machine.max_jerk)))


def test_a_start_off_the_path_is_settled_without_a_jolt(corner):
    assert _jerk_share(corner) <= 1.0 + 1e-6


def test_without_settling_the_first_step_jolts(corner, monkeypatch):
    monkeypatch.setattr(cut_rows, "SETTLE_STEPS", 0)
    assert _jerk_share(corner) > 2.0
