"""The gate and the simulation agree, over several setups: six_pockets' `pencil --setups
auto` programs (exit 0, so gated) simulated together take no part material deeper than the
gate's limit, and leave in each pocket's floor / wall corner what a ball of R must leave
there and no more: R - sqrt(R^2 - (R - w)^2) at distance w from the wall, within the
resolution."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.simulation.simulator import simulate
from helpers.cli import cadcnc_cli
from helpers.six_pockets import AXES, FACTS, STEP, R

pytestmark = pytest.mark.slow

RES = 0.1


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("six")
    cadcnc_cli("pencil", STEP, "--radius", R, "--setups", "auto", "-o", out / "P.json",
               check=0)
    programs = sorted(out.glob("P*.json"))
    assert len(programs) == 6
    return simulate(cadcnc.load_step(STEP), programs, resolution=RES, jobs=2)


def test_the_gated_programs_take_no_part_material(report):
    assert report.data["gouges"] == []
    assert len(report.data["programs"]) == 6
    assert {tuple(p["axis"]) for p in report.data["programs"]} == set(AXES.values())


@pytest.mark.parametrize("side", sorted(AXES))
def test_every_corner_holds_only_what_the_ball_must_leave(report, side):
    s = report.samples
    facts = FACTS["sides"][side]
    floor = s.face == facts["floor"]
    # the wall is e . p = -8 (e: "across", into the pocket); w: a floor sample's distance
    # from it; the corner runs along d x e (d the side's axis)
    e = np.asarray(facts["across"], float)
    w = s.point @ e + 8.0
    along = s.point @ np.cross(AXES[side], e)
    lo, hi = along[floor].min(), along[floor].max()
    corner = floor & (w > 0) & (w < 0.95 * R) & (along > lo + 2 * R) & (along < hi - 2 * R)
    assert corner.sum() > 20
    must = R - np.sqrt(R * R - (R - w[corner]) ** 2)
    assert np.abs(s.left[corner] - must).max() <= RES
