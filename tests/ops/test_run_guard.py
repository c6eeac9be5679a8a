"""The stepper of a cut asks its guard at every cycle (ops.common.run_stretch).

The compiled stepper reads its guard when it is built; a guard assigned afterwards was
never asked while trials passed, so no collision stop happened inside a cut (r0901_ec,
faces 105/248 at R 2: a 0.004 mm stretch cut 9.3 mm on, its shank 2 mm into face 105).
Here a guard that clears 5 mm of travel from the start must stop the floor-wall cut of
the pocket fixture there, on the guard's zero, whatever the stepper."""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.interp.cycle import COLLISION
from cadcnc.ops.common import run_stretch
from cadcnc.ops.path.pair_path import pair_job, plan_path
from helpers.fixtures import SIDECAR, load_fixture


class FiveMillimetres:
    """Clear within 5 mm (straight line) of ``start``, a hit beyond: margin in mm."""

    def __init__(self, start):
        self.start = np.asarray(start, float)
        self.calls = 0

    def margin(self, p):
        self.calls += 1
        return 5.0 - float(np.linalg.norm(np.asarray(p, float) - self.start)), "face 99"


def _faces(role: str) -> int:
    return next(int(n) for n, f in SIDECAR["pocket"]["faces"].items()
                if f["role"].startswith(role))


@pytest.mark.parametrize("compiled", [True, False])
def test_a_cut_stops_where_its_guard_says(compiled, monkeypatch):
    from functools import partial

    from cadcnc.interp.compiled import new_stepper
    from cadcnc.ops.path import pair_path

    monkeypatch.setattr(pair_path, "new_stepper", partial(new_stepper, compiled=compiled))
    part = load_fixture("pocket")
    s1, s2, job = pair_job(part.face(_faces("pocket planar wall x=-30")),
                           part.face(_faces("pocket floor z=15")), radius=3.0, feed=1500.0,
                           period=0.004)
    plan = plan_path(s1, s2, job)
    guard = FiveMillimetres(plan.start.p)
    tp = run_stretch(plan, guard, 100_000, None)
    travelled = np.linalg.norm(tp.points[-1] - np.asarray(plan.start.p))
    assert tp.stop_reason == COLLISION, tp.stop_detail
    assert travelled == pytest.approx(5.0, abs=1e-6)
    assert guard.calls >= 50   # asked at every cycle (0.1 mm each), not only on landing
