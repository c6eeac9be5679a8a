"""``clears(p)``, the guard's yes or no (the setups' reach samples), says what
``margin(p) >= 0`` says: at random ball centres about bspline_boss's pair 4/5, each guard
asked in the same order."""

from __future__ import annotations

import numpy as np

import cadcnc
from cadcnc.core.job import Job, Pencil, Tool
from cadcnc.guard import guard_for
from helpers.fixtures import FIXTURES


def test_clears_is_margin_not_negative():
    part = cadcnc.load_step(FIXTURES / "bspline_boss.step")
    job = Job(Tool(3.0), 1500.0, 0.004, Pencil())
    yes_no, full = guard_for(part, (4, 5), job), guard_for(part, (4, 5), job)
    lo, hi = part.face(4).box()
    rng = np.random.default_rng(4)
    answers = []
    for _ in range(24):
        p = tuple(rng.uniform(np.asarray(lo) - 3.0, np.asarray(hi) + 3.0).tolist())
        answers.append(yes_no.clears(p))
        assert answers[-1] == (full.margin(p)[0] >= 0.0), p
    assert any(answers) and not all(answers)   # both answers met
