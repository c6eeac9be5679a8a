"""Issue 20 on the finishing side: crossings paired by their order along the pass, no false
partial on a boss climbed, bounded work refused up front with the estimate and the option,
and progress inside a plane at least every 5 s (fake clock).

Fixtures: finish_boss (a free-form top around a vertical cylindrical boss r 4 at (5, 2),
fixtures/finish_fixtures.json), finish_slab, and a horizontal cylinder sitting on a block
built here with CadQuery. Facts come from the fixtures' closed forms, never from the pass.
"""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import InputError
from cadcnc.core.job import Job, Raster, Tool
from cadcnc.core.work_limits import HEARTBEAT_S, MAX_PLANES, WorkLimitError
from cadcnc.ops.finish.check import planned_intervals
from cadcnc.ops.finish.pass_setup import pass_setup
from cadcnc.ops.finish.passes import GuidePlane, _Pass
from cadcnc.ops.finish.plan import centre_chord
from cadcnc.ops.finish.raster import raster_program
from cadcnc.program.program import FAILED, STOPPED_SHORT
from helpers.fixtures import FIXTURES

pytestmark = pytest.mark.slow  # over about 5 s a test (pyproject.toml)

FACTS = json.loads((FIXTURES / "finish_fixtures.json").read_text())
R = 3.0
_parts: dict = {}


def part_of(name: str):
    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIXTURES / FACTS[name]["file"])
    return _parts[name]


def finish_job(faces, stepover=None, scallop=None, radius=R, angle=0.0):
    return Job(Tool(radius), 1500.0, 0.004, Raster(tuple(faces), stepover, scallop, angle))


def boss_pass(offset: float, reverse: bool):
    """The pass of finish_boss's top and boss wall (faces 6 7) on plane y = offset."""
    part = part_of("boss")
    faces = (FACTS["boss"]["top"], FACTS["boss"]["boss_face"])
    job = finish_job(faces, stepover=4.0)
    ps = _Pass(pass_setup(part, faces, job), GuidePlane(0.0, offset), job, reverse, None)
    return ps, ps.run()


def bad(result):
    return [s.detail for s in result.skipped if s.reason in (STOPPED_SHORT, FAILED)]


# -- 1. crossings paired by their order along the pass ----------------------------------

def test_a_plane_through_the_boss_seam_finds_one_crossing_per_point():
    """Plane y = 2 holds the boss's axis and the seam vertex of its circular edges: each
    edge crosses the plane once on each side of the boss (x = 5 +- (4 + R')), no point
    twice and none missed; the climb reaches its exit at the top, not "stopped short of
    its planned exit" on the far side."""
    x, y, r = *FACTS["boss"]["boss_axis"], FACTS["boss"]["boss_radius"]
    ps, res = boss_pass(y, True)
    wall = ps.crossings[FACTS["boss"]["boss_face"]]
    assert len(wall) == 4
    xs = sorted(round(float(c.point[0]), 6) for c in wall)
    assert xs == pytest.approx([x - r - R] * 2 + [x + r + R] * 2, abs=1e-6)
    assert sorted(c.entry for c in wall) == [False, False, True, True]
    assert bad(res) == []
    climbs = [c for c in res.cuts if c.path.faces[0] == FACTS["boss"]["boss_face"]]
    assert len(climbs) == 2   # up the near side, down the far side: each once


@pytest.mark.parametrize("offset,reverse", [(-2.0, True), (6.0, True), (2.0, False)])
def test_a_boss_climbed_is_no_false_partial(offset, reverse):
    """Faces 6 and 7 (top and boss wall), stepover 4 (issue 20: exit 6 with an empty
    reason): the top's curve between the tri-tangent point and its edge lies in the
    wall's shadow, accounted for; each wall stretch is cut once, and every cut point is
    R' from the boss's axis or on the top's side."""
    x, y, r = *FACTS["boss"]["boss_axis"], FACTS["boss"]["boss_radius"]
    ps, res = boss_pass(offset, reverse)
    assert bad(res) == []
    assert res.cuts
    wall = [c for c in res.cuts if c.path.faces[0] == FACTS["boss"]["boss_face"]]
    for c in wall:   # the ball touches the cylinder: its centre r + R' from the axis
        rho = np.hypot(c.points[:, 0] - x, c.points[:, 1] - y)
        assert np.abs(rho - (r + R)).max() < 1e-6
    keys = [tuple(np.round(c.points[[0, -1]].ravel(), 6)) for c in res.cuts]
    assert len(set(keys)) == len(keys)   # no stretch cut twice
    covered = sum(b - a for a, b in planned_intervals(ps.crossings, ps.travel))
    assert covered > 0


def test_wall_crossings_at_one_s_are_ordered_by_height():
    """On a wall climbed, the entry at its foot comes before the exit at its top along
    the pass, whatever the rounding of s: the planned interval of the wall has no
    length (it does not reach over the boss's top to the far side)."""
    ps, _ = boss_pass(-2.0, True)
    wall = {FACTS["boss"]["boss_face"]: ps.crossings[FACTS["boss"]["boss_face"]]}
    for a, b in planned_intervals(wall, ps.travel):
        assert b - a < 1e-6


def horizontal_cylinder():
    """A block 40 x 30 x 10 with a cylinder r 5, axis along Y at z 13, fused on its top
    (its face wraps under the equator down to the block: an underside on both sides)."""
    import cadquery as cq  # only this test builds a part (about 3 s to import)

    from cadcnc.geometry.part import Part

    base = cq.Workplane().box(40, 30, 10, centered=(True, True, False)).val()
    cyl = cq.Solid.makeCylinder(5.0, 20.0, cq.Vector(0, -10, 13.0), cq.Vector(0, 1, 0))
    return Part.from_cadquery(base.fuse(cyl).clean())


def test_a_horizontal_cylinder_on_a_plane_along_its_axis_is_complete():
    """Passes along the axis of a horizontal cylinder sitting on a block (angle 90):
    the planes through its circular edges' seam vertices on the underside pair their
    crossings along the pass; no cut is stopped short of a planned exit."""
    part = horizontal_cylinder()
    face = next(f.number for f in part.faces if f.kind == "cylinder")
    job = finish_job((face,), stepover=2.0, angle=90.0)
    setup = pass_setup(part, (face,), job)
    offsets = {0.0, -3.5, 3.5}
    for edge in setup.edges[face].edges:   # planes through every vertex of the face
        for t in (edge.t0, edge.t1):
            c = setup.edges[face].centre(edge, t)[0]
            offsets.add(round(float(c @ GuidePlane(90.0, 0.0).normal), 9))
    for off in sorted(offsets):
        for reverse in (False, True):
            ps = _Pass(setup, GuidePlane(90.0, off), job, reverse, None)
            res = ps.run()
            assert bad(res) == [], (off, reverse)


# -- 3. bounded work, refused up front ---------------------------------------------------

@pytest.mark.parametrize("kw,option", [
    (dict(stepover=1e-9), "--stepover"),
    (dict(scallop=1e-12), "--scallop"),
    (dict(stepover=1.0, radius=1e6), "--radius"),
])
def test_too_many_planes_are_refused_with_the_estimate_and_the_option(kw, option):
    part = part_of("slab")
    with pytest.raises(WorkLimitError, match="guide planes") as err:
        raster_program(part, finish_job(FACTS["slab"]["faces"], **kw))
    assert option in str(err.value) and f"{MAX_PLANES:g}" in str(err.value)
    assert err.value.exit_code == 2


def test_a_huge_scallop_spaces_the_planes_by_the_ball_width():
    """--scallop 1e6: a cusp can be no higher than the ball, so the planes are 2 R apart
    (not NaN); the program is complete."""
    assert float(centre_chord(1e6, 0.0, R)) == pytest.approx(2 * R, rel=1e-12)
    work: dict = {}
    program = raster_program(part_of("slab"), finish_job(FACTS["slab"]["faces"],
                                                         scallop=1e6), work=work)
    assert program.complete and work["planes"] >= 1
    assert work["planes"] <= 1.5 * work["planes_estimate"]


@pytest.mark.parametrize("kw", [dict(scallop=0.002), dict(scallop=0.05), dict(stepover=0.5)])
def test_the_counted_planes_stay_within_the_estimate(kw):
    """Planes are estimated before any is placed; the count stays within 1.5 times the
    estimate (and the estimate within 2.5 times the count)."""
    from cadcnc.ops.finish.raster import plan_for_job

    for name in ("slab", "ridge"):
        work: dict = {}
        plan, _ = plan_for_job(part_of(name), finish_job(FACTS[name]["faces"], **kw),
                               work=work)
        n = len(plan.offsets)
        assert n <= 1.5 * work["planes_estimate"], (name, n, work)
        assert work["planes_estimate"] <= 2.5 * n, (name, n, work)


def test_the_plane_limit_is_a_keyword():
    with pytest.raises(WorkLimitError, match="over the limit of 3"):
        raster_program(part_of("slab"), finish_job(FACTS["slab"]["faces"], stepover=1.0),
                       max_planes=3)


def test_a_scallop_too_small_for_floats_is_a_clear_error():
    with pytest.raises(InputError):
        raster_program(part_of("slab"), finish_job(FACTS["slab"]["faces"], scallop=1e-300))


# -- 4. never silent for more than 5 s ---------------------------------------------------

def test_progress_comes_at_least_every_5_s_inside_a_plane():
    """A fake clock that moves 3 s at every reading: a plane reports while its pass runs
    (its pieces, the stepper's cycles), and no two reports are more than 5 s (+ one
    reading) apart."""
    ticks = itertools.count()
    now = [0.0]

    def clock():
        now[0] = 3.0 * next(ticks)
        return now[0]

    seen = []
    raster_program(part_of("slab"), finish_job(FACTS["slab"]["faces"], stepover=10.0),
                   clock=clock, progress=lambda done, total, what: seen.append(
                       (now[0], done, total, what)))
    inside = [s for s in seen if "cycles" in s[3] or "cutting" in s[3]]
    assert len(inside) >= 2
    assert all(what.startswith(f"plane {done + 1}:") for _, done, _, what in inside)
    times = [t for t, *_ in seen]
    assert max(np.diff(times)) <= HEARTBEAT_S + 3.0
    assert seen[-1][1] == seen[-1][2]
    assert math.isfinite(times[-1])
