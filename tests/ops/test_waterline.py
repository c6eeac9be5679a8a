"""Waterline finishing: loops exact on the offset surfaces (OCCT's distance), closed loops
closed, loop counts equal to OCCT's section of the offset faces, levels moved off
horizontal faces and tangencies, bad levels refused."""

from __future__ import annotations

import json
import math

import cadquery as cq
import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import InputError
from cadcnc.core.job import Job, SteepShallow, Tool, Waterline, finishing
from cadcnc.core.work_limits import WorkLimitError
from cadcnc.geometry.offset_section import loop_count, offset_face
from cadcnc.ops.finish.levels import CRITICAL_MM, critical_heights, plan_levels
from cadcnc.ops.finish.loops import level_cuts
from cadcnc.ops.finish.pass_setup import pass_setup
from cadcnc.ops.finish.plan import sample_faces
from cadcnc.verification.probe import shape_distances
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "waterline_fixtures.json").read_text())
RADIUS = {"dome": 3.0, "wall": 3.0, "boss": 2.0}
# levels (centre z, mm) per fixture: closed loops (dome high), open pieces (dome low, the
# wall), circles across the seam of the boss wall and its fillet (torus)
LEVELS = {"dome": (19.5, 13.1), "wall": (10.0,), "boss": (12.0, 7.8)}
_cache: dict = {}


def fixture(name: str):
    """(part, job, setup, offset faces) of a waterline fixture, built once."""
    if name not in _cache:
        part = cadcnc.load_step(FIXTURES / FACTS[name]["file"])
        faces = FACTS[name]["faces"]
        job = Job(Tool(RADIUS[name]), 1500.0, 0.004,
                  Waterline(faces, stepdown=1.0))
        offs = {f: offset_face(part.face(f).topods, job.tool.offset) for f in faces}
        _cache[name] = (part, job, pass_setup(part, faces, job), offs)
    return _cache[name]


def chains(cuts, join=1e-6) -> list[list]:
    """The cuts grouped into chains (each next starting where the last ended)."""
    out: list[list] = []
    for c in cuts:
        if out and np.linalg.norm(out[-1][-1].points[-1] - c.points[0]) <= join:
            out[-1].append(c)
        else:
            out.append([c])
    return out


@pytest.mark.parametrize("name,z", [(n, z) for n, zs in LEVELS.items() for z in zs])
def test_loops_are_exact_closed_and_counted(name, z):
    part, job, setup, offs = fixture(name)
    res = level_cuts(setup, offs, z, job, "climb")
    assert res.cuts and not res.skipped, [s.detail for s in res.skipped]
    rp = job.tool.offset
    for cut in res.cuts:
        pts = cut.points
        face = part.face(cut.path.faces[0]).topods
        assert np.abs(pts[:, 2] - z).max() <= 1e-9
        sel = pts[:: max(1, len(pts) // 25)]
        assert np.abs(shape_distances(face, sel) - rp).max() <= 1e-9
        mids = 0.5 * (pts[1:] + pts[:-1])
        worst = np.argsort(np.linalg.norm(np.diff(pts, axis=0), axis=1))[-10:]
        assert np.abs(shape_distances(face, mids[worst]) - rp).max() <= 1e-3
        if cut.path.stop_reason == "closed":
            assert np.linalg.norm(pts[0] - pts[-1]) <= 1e-9
    closed, opened = loop_count(list(offs.values()), z)
    got = chains(res.cuts)
    shut = sum(np.linalg.norm(c[0].points[0] - c[-1].points[-1]) <= 1e-9 for c in got)
    assert (shut, len(got) - shut) == (closed, opened)


def test_climb_and_conventional_run_opposite_ways():
    """Climb runs clockwise round the boss seen from +Z (material on the right),
    conventional anticlockwise: the sign of the swept area."""
    _, job, setup, offs = fixture("boss")
    area = {}
    for side in ("climb", "conventional"):
        p = level_cuts(setup, offs, 12.0, job, side).cuts[0].points
        area[side] = 0.5 * float(np.sum(p[:-1, 0] * p[1:, 1] - p[1:, 0] * p[:-1, 1]))
    r = FACTS["boss"]["boss_radius"] + RADIUS["boss"]
    assert area["climb"] == pytest.approx(-math.pi * r * r, rel=1e-4)
    assert area["conventional"] == pytest.approx(math.pi * r * r, rel=1e-4)


def test_levels_move_off_a_horizontal_face_and_a_tangency():
    """Boss, R' 2: its top's offset is at z 17 (the top of the faces), the fillet's foot a
    horizontal tangency at z 5 + 2 = 7; a 1 mm stepdown from 17 puts levels exactly at
    both, which move by half a stepdown; the levels moved to still count OCCT's loops."""
    part, job, setup, offs = fixture("boss")
    samples = sample_faces(part, FACTS["boss"]["faces"], 0.25)
    crit = critical_heights(part, FACTS["boss"]["faces"], samples, 2.0)
    heights = sorted(z for z, _ in crit)
    assert heights[0] == pytest.approx(7.0, abs=1e-9)
    assert heights[-1] == pytest.approx(17.0, abs=1e-12)
    plan = plan_levels(samples, 2.0, 0.0, stepdown=1.0, critical=crit)
    assert plan.offsets[0] == pytest.approx(16.5, abs=1e-12)
    assert plan.offsets[-1] == pytest.approx(7.5, abs=1e-12)
    assert all(abs(z - c) > CRITICAL_MM for z in plan.offsets for c in heights)
    assert len(plan.moved) == 2 and plan.flat_area > 190.0   # the top, r 8: 201 mm^2
    for z in (plan.offsets[0], plan.offsets[-1]):
        res = level_cuts(setup, offs, float(z), job, "climb")
        assert len(chains(res.cuts)) == sum(loop_count(list(offs.values()), float(z)))


def test_dome_top_is_a_tangency_found_exactly():
    part, _, _, _ = fixture("dome")
    samples = sample_faces(part, FACTS["dome"]["faces"], 0.5)
    crit = critical_heights(part, FACTS["dome"]["faces"], samples, 3.0)
    face = part.face(FACTS["dome"]["faces"][0])
    top = max(z for z, _ in crit)
    # every sample's centre is below it, and the nearest within the sampling's reach
    f = samples.points[:, 2] + 3.0 * samples.normals[:, 2]
    assert f.max() <= top + 1e-12 and top - f.max() < 0.01
    assert face.kind == "bspline"


@pytest.mark.parametrize("kw,words", [
    (dict(strategy="waterline"), "exactly one of stepdown and scallop"),
    (dict(strategy="waterline", stepover=1.0), "stepover 1"),
    (dict(strategy="waterline", stepdown=-1.0), "stepdown"),
    (dict(strategy="steep-shallow", scallop=0.01, threshold=90), "threshold"),
    (dict(strategy="steep-shallow", stepdown=1.0), "both stepover"),
    (dict(strategy="zigzag", stepover=1.0), "strategy"),
    (dict(strategy="waterline", stepdown=1.0, side="left"), "side"),
    (dict(strategy="steep-shallow", scallop=0.01, overlap=-1), "overlap"),
])
def test_bad_strategy_fields_are_refused(kw, words):
    with pytest.raises(InputError, match=words):
        finishing(kw.pop("strategy"), [5], **kw)


def test_levels_are_estimated_and_bounded_before_any_is_cut():
    part, _, _, _ = fixture("wall")
    with pytest.raises(InputError, match="diameter"):
        cadcnc.finish(part, FACTS["wall"]["faces"], radius=3.0, strategy="waterline",
                      stepdown=7.0)
    with pytest.raises(WorkLimitError, match="--stepdown"):
        cadcnc.finish(part, FACTS["wall"]["faces"], radius=3.0, strategy="waterline",
                      stepdown=0.01, max_planes=100)


def test_the_job_records_the_strategy():
    op = SteepShallow([5], stepover=1.0, stepdown=0.5, threshold=30,
                      side="conventional", overlap=0.5)
    job = Job(Tool(3.0), 1500.0, 0.004, op)
    again = Job.from_inputs(json.loads(json.dumps(job.to_inputs())))
    assert again.operation == op


def test_two_loops_on_one_face_are_both_cut():
    """A torus's outer face cut by a level gives two circles on the same face: the pieces
    of one face differ only in their arrays, and choosing the nearest must not compare
    them (comparing their arrays raised a ValueError: exit 1 on bug28414's torus)."""
    torus = cq.Workplane().add(cq.Solid.makeTorus(20.0, 6.0))
    part = cadcnc.Part.from_cadquery(torus)
    job = Job(Tool(3.0), 1500.0, 0.004, Waterline(faces=(1,), stepdown=5.0),
              source=part.source)
    program = cadcnc.run(part, job)
    assert program.complete
    at = {}
    for cut in program.cuts:
        z = round(float(cut.points[0][2]), 6)
        at.setdefault(z, []).append(cut)
    assert any(len(cuts) >= 2 for cuts in at.values()), {z: len(c) for z, c in at.items()}
