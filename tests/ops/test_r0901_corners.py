"""Two corners of r0901_ec.stp that a -Z setup stopped short on (issue 23), cut complete.

Fixtures (fixtures/build_r0901_corners.py, cut from OCCT's r0901_ec.stp):

- ``r0901_near_tangent``: the faces turn tangent at one end of the corner. The stretch
  started at |n1 x n2| = 0.01 (the stepper's tangent limit), where the stepper's own
  estimate read 0.0099 after one step: the cut stopped 0.056 mm into a 2.9 mm stretch
  (exit 6). The search now keeps a margin (``Tolerances.stretch_tangent_sin``).
- ``r0901_reversed``: the ball centre runs against the edge's own direction, so the cut
  sent along the edge's tangent stepped off its stretch at once (exit 6). The cut now
  starts towards the stretch's next centre.

And a search that does not depend on the work zero (a sample seeded on the wrong branch
is solved again from the anchor, ``stretches.RESEED``).

Judged by OCCT, not by our classifier or kernel: the cut points lie R' from both faces
and no face of the part is nearer; the tangent limits' exact contacts (Newton) give
|n1 x n2| at the margin.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

import cadcnc
from cadcnc.core.tolerances import DEFAULT
from cadcnc.geometry.setup import job_setup, setup_part
from cadcnc.interp.cycle import Contact
from cadcnc.ops.path.feasibility import TANGENT
from cadcnc.ops.path.stretches import pair_stretches
from cadcnc.testing.occt import occt_distance as distance
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "r0901_corners.json").read_text())
_cache: dict = {}


def job(name: str) -> cadcnc.Job:
    f = FACTS[name]
    return cadcnc.Job(cadcnc.Tool(f["radius"]), 1500.0, 0.004,
                      cadcnc.PairPath(faces=tuple(f["faces"]), edge=None), axis=f["axis"])


def part(name: str):
    if name not in _cache:
        _cache[name] = cadcnc.load_step(FIXTURES / FACTS[name]["file"])
    return _cache[name]


def program(name: str):
    key = ("program", name)
    if key not in _cache:
        _cache[key] = cadcnc.run(part(name), job(name))
    return _cache[key]


def stretches(name: str):
    j = job(name)
    sp = setup_part(part(name), j)
    i, k = FACTS[name]["faces"]
    return pair_stretches(sp.face(i), sp.face(k), j)


@pytest.mark.parametrize("name", sorted(FACTS))
def test_every_stretch_is_cut_to_its_limits(name):
    prog = program(name)
    assert prog.complete, prog.partial_reasons
    assert not prog.skipped
    assert prog.cut_length > 0.2
    n = sum(len(e.stretches) for e in stretches(name))
    assert len(prog.cuts) == n


@pytest.mark.parametrize("name", sorted(FACTS))
def test_cut_points_lie_on_the_offsets_by_occt(name):
    """Every 3rd cut point (part coordinates): R' from both faces within the spec's 1 um
    (near tangency the stepper's points lie up to 0.06 um inside), no face nearer."""
    p, prog = part(name), program(name)
    r = FACTS[name]["radius"]
    faces = [p.face(n).topods for n in FACTS[name]["faces"]]
    setup = job_setup(job(name), p)
    for seg in prog.cuts:
        for q in setup.to_part(seg.path.points)[::3]:
            for f in faces:
                assert distance(q, f) == pytest.approx(r, abs=DEFAULT.accuracy)
            assert distance(q, p.given_shape) > r - DEFAULT.gouge


def test_tangent_limits_keep_the_margin():
    """A stretch ending where the faces turn tangent ends at |n1 x n2| = 0.02 (twice the
    stepper's limit), its exact contacts' normals, not the stepper's."""
    j = job("r0901_near_tangent")
    limits = [lim for e in stretches("r0901_near_tangent") for st in e.stretches
              for lim in (st.start, st.end) if lim.rule == TANGENT]
    assert limits
    i, k = (setup_part(part("r0901_near_tangent"), j).face(n)
            for n in FACTS["r0901_near_tangent"]["faces"])
    for lim in limits:
        t = lim.tangency
        n1 = Contact(i, j.offsets[0], *t.uv1).n
        n2 = Contact(k, j.offsets[1], *t.uv2).n
        sin = float(np.linalg.norm(np.cross(n1, n2)))
        assert DEFAULT.stretch_tangent_sin <= sin < DEFAULT.stretch_tangent_sin * 1.01


def test_a_cut_starts_towards_its_stretch():
    """On the reversed corner the centre runs against the edge: each stretch's direction
    points from its start towards its end, and the edge's tangent does not."""
    against = 0
    for e in stretches("r0901_reversed"):
        for st in e.stretches:
            chord = np.subtract(st.end.p, st.start.p)
            assert np.dot(st.direction, chord) > 0.0
            a, tangent = e.curve.point_tangent(st.start.s)
            against += np.dot(tangent, chord) < 0.0
    assert against >= 1


def test_the_corner_does_not_depend_on_the_work_zero():
    """The same program (part coordinates) whatever the work zero, to the accuracy of its
    stretch limits (``Tolerances.stretch_limit``: the grids' samples differ between the
    frames by round-off, so the root search starts from other brackets; 5e-6 mm here).
    Before, with the zero at the part's origin the search's first sample solved on
    another offset intersection curve (its contact on the cylinder off the face) and
    followed it: "no feasible ball position" (exit 3) for a corner cut complete with the
    default zero."""
    name = "r0901_near_tangent"
    p, base = part(name), job(name)
    expected = job_setup(base, p).to_part(
        np.concatenate([c.path.points for c in program(name).cuts]))
    for origin in ((0.0, 0.0, 0.0), (100.0, -50.0, 20.0)):
        j = replace(base, origin=origin)
        got = job_setup(j, p).to_part(
            np.concatenate([c.path.points for c in cadcnc.run(p, j).cuts]))
        assert got.shape == expected.shape
        assert np.abs(got - expected).max() < DEFAULT.stretch_limit
