"""Corners no plunge from above reaches: a sealed void taller than the shank (issue 12's
"not reachable from +Z", left out of coverage). The judge's verdict and pencil's skip."""

from __future__ import annotations

import cadquery as cq
import numpy as np
import pytest

from cadcnc.geometry.part import Part
from cadcnc.ops.pencil.pencil_program import NOT_REACHABLE
from cadcnc.verification import gouge_gate
from helpers.programs import pencil_run

RADIUS = 1.0   # shank 10 mm, shorter than the 30 mm void


@pytest.fixture(scope="module")
def shape():
    """Block 60 x 40 x 40 with a sealed void 5..25 x 10..30 x 5..35 and an open pocket
    35..55 x 10..30 from the top down to z 20."""
    block = cq.Workplane().box(60, 40, 40, centered=False)
    void = cq.Workplane().box(20, 20, 30, centered=False).translate((5, 10, 5))
    pocket = cq.Workplane().box(20, 20, 20, centered=False).translate((35, 10, 20))
    return block.cut(void).cut(pocket).val()


def _oracle():
    from cadcnc.testing import coverage_oracle

    return coverage_oracle


def test_judge_calls_the_void_floor_unreachable(shape):
    """At the void's floor corners the ball and a 10 mm shank fit (the spec's four rules),
    but the shank continued up meets the void's ceiling z 35: `unreachable`. The open
    pocket's floor corners are `feasible`. Closed form: centres at z = floor + R'."""
    oracle_mod = _oracle()
    o = oracle_mod.Oracle(shape.wrapped)
    verdicts = {"void": set(), "pocket": set()}
    for e in o.concave_edges():
        t = o.samples(e)[len(o.samples(e)) // 2]
        v = o.judge(e, t, RADIUS, 10 * RADIUS)
        p = np.array(v["p"])
        if abs(p[2] - (5 + RADIUS)) < 1e-6 and p[0] < 30:
            verdicts["void"].add(v["verdict"])
        if abs(p[2] - (20 + RADIUS)) < 1e-6 and p[0] > 30:
            verdicts["pocket"].add(v["verdict"])
    assert verdicts == {"void": {"unreachable"}, "pocket": {"feasible"}}


def test_pencil_skips_cuts_no_plunge_reaches(shape):
    """Pencil cuts the open pocket and skips the void's corners as not reachable from +Z
    (before, the plunge into the void made the gate refuse the whole program)."""
    part = Part.from_cadquery(shape)
    prog = pencil_run(part, radius=RADIUS)
    unreachable = [s for s in prog.skipped if s.reason == NOT_REACHABLE]
    assert unreachable and all("on the way to Z" in s.detail for s in unreachable)
    assert prog.cuts and all(c.points[:, 0].min() > 30.0 for c in prog.cuts)
    floor = [c for c in prog.cuts if np.allclose(c.points[:, 2], 20 + RADIUS, atol=1e-6)]
    assert len(floor) == 4
    gate = gouge_gate(prog.cuts[0].path, part, moves=prog.all_moves())
    assert gate.ok, gate.message
