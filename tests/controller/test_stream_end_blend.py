"""A cut's last BLEND mm move the kernel's target onto the distance left to the end, which
absorbs the difference between the program's arc length and the kernel's own path (a few
1e-7 of the cut's length). That move adds about 60 x the difference x (v / BLEND)³ to the
jerk. Here the corner cut's arc lengths are made 3e-6 of its length too long (0.2 µm on
70 mm) and its stream, planned once (no replan), is checked by finite differences:
within every limit at BLEND = 1 mm, over the jerk at the earlier 0.2 mm."""

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
from helpers.fixtures import FIXTURES

OFF = 3e-6   # the arc lengths' share too long


@pytest.fixture(scope="module")
def corner():
    part = cadcnc.load_step(FIXTURES / "bspline_boss.step")
    _, _, job = pair_job(part.face(4), part.face(5), radius=3.0, feed=1500.0, period=0.004)
    return part, program_for_job(part, job)


def _jerk_share(corner, blend: float, monkeypatch, measured: bool = False) -> float:
    """The largest third difference of the positions over its axis's jerk limit, the
    stream planned once with the cuts' arc lengths OFF too long (``measured``: the
    bending run's limits where they are, as a stream's first plan takes them)."""
    part, program = corner
    machine = Machine.default()
    monkeypatch.setattr(cut_rows, "BLEND", blend)
    pieces = [dataclasses.replace(p, s=p.s * (1.0 + OFF)) if p.cut is not None else p
              for p in st.stream_pieces(program, machine, 10_000.0)]
    stream = st._stream(program, machine, pieces, stepper_factory(part), True, np.ones(3),
                        st.MAX_PERIODS, None, measured=measured)
    jerk = np.abs(np.diff(stream.positions, 3, axis=0)) / machine.period ** 3
    return float(np.max(jerk / np.asarray(machine.max_jerk)))


@pytest.mark.parametrize("measured", [False, True])
def test_the_end_blend_keeps_the_jerk_within_its_limit(corner, monkeypatch, measured):
    assert _jerk_share(corner, cut_rows.BLEND, monkeypatch, measured) <= 1.0


def test_a_short_end_blend_breaks_it(corner, monkeypatch):
    """On the plan with the bending run's limits held (the corner's measured plan ends
    its cut more gently: 0.995 of the jerk)."""
    assert _jerk_share(corner, 0.2, monkeypatch) > 1.01   # 1.031 when written
