"""A gap in a corner shorter than the stretch search's spacing: an expected end, not a stop.

Fixture ``stretch_grazed_hole`` (fixtures/build_grazed_hole.py; the geometry class of
bug27453_165-174_piattello.stp faces 11 / 14, issue 23): a hole in the floor crosses the
floor contact line of the floor / wall corner over 0.2 mm, between two of the search's
samples (0.4 mm apart). Before the fix, the search ran one stretch across the gap and
the cut stopped short at it (``boundary``: exit 6). Judged by OCCT, not by our
classifier: positions in the gap touch the floor off the face (BRepExtrema distance to
the floor > 0); the two limits touch the hole's rim; every cut point lies R' from the
floor and the wall, and no face of the part is nearer. Also: a part turned into a setup
keeps its coordinates when rebuilt in a worker (the gate's processes).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import cadcnc
from cadcnc.core.tolerances import DEFAULT
from cadcnc.geometry.part_bytes import part_blob, part_from_blob
from cadcnc.geometry.setup import setup_in, setup_part
from cadcnc.ops.path.pair_path import pair_job
from cadcnc.ops.path.stretch_split import split_at_stop
from cadcnc.ops.path.stretches import pair_stretches
from cadcnc.testing.occt import occt_distance as distance
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "grazed_hole.json").read_text())
R = FACTS["radius"]
_cache: dict = {}


def part():
    if "part" not in _cache:
        _cache["part"] = cadcnc.load_step(FIXTURES / FACTS["file"])
    return _cache["part"]


def program():
    if "program" not in _cache:
        job = cadcnc.Job(cadcnc.Tool(R), 1500.0, 0.004, cadcnc.PairPath(
            faces=tuple(FACTS["pair"])))
        _cache["program"] = cadcnc.run(part(), job)
    return _cache["program"]


def test_the_gap_is_real_by_occt():
    """The fixture: in the gap the floor contact lies off the floor (the premise)."""
    floor = part().face(FACTS["pair"][0]).topods
    (start, end), (start2, _) = FACTS["stretches"]
    y, z = start[1], start[2] - R
    assert distance((0.5 * (end[0] + start2[0]), y, z), floor) > 1e-3
    for x in (end[0] - 0.1, start2[0] + 0.1):   # the search's neighbouring samples
        assert distance((x, y, z), floor) < 1e-9


def test_a_gap_between_samples_ends_the_stretch():
    """Two complete cuts, one each side of the gap, ending on the hole's rim."""
    prog = program()
    assert prog.complete, prog.partial_reasons
    assert not prog.skipped
    cuts = sorted((seg.path for seg in prog.cuts), key=lambda tp: tp.points[:, 0].min())
    assert len(cuts) == 2
    hole = part().face(FACTS["hole_face"][0]).topods
    for tp, (a, b) in zip(cuts, FACTS["stretches"]):
        pts = tp.points[np.argsort(tp.points[:, 0])]
        lo, hi = pts[0], pts[-1]
        # the contact 1 um off the floor moves a limit up to 1 / sin(1.76 deg) = 33 um
        # along the line into the gap; the outer limits (end walls) to ~1 um
        assert lo[0] == pytest.approx(a[0], abs=40e-6) and hi[0] == pytest.approx(
            b[0], abs=40e-6)
        assert np.abs(pts[:, 1:] - a[1:]).max() < 1e-9
        assert np.diff(pts[:, 0]).max() <= 0.1 + 1e-9    # no hole in the cut itself
    gap = (cuts[0].points[:, 0].max(), cuts[1].points[:, 0].min())
    (_, end), (start2, _) = FACTS["stretches"]
    # each inner limit past the hole's rim by the boundary's 1 um, or short of it by at
    # most the limit's accuracy (the feasible side)
    limit = DEFAULT.stretch_limit
    assert end[0] - limit <= gap[0] < gap[1] <= start2[0] + limit
    for x in gap:   # the inner limits' floor contacts lie on the hole's rim
        assert distance((x, end[1], end[2] - R), hole) < 2e-6


def test_cut_points_lie_on_the_offsets_by_occt():
    """Every 5th point of each cut: R' from the floor and the wall, no face nearer."""
    floor, wall = (part().face(n).topods for n in FACTS["pair"])
    shape = part().given_shape
    for seg in program().cuts:
        for p in seg.path.points[::5]:
            assert distance(p, floor) == pytest.approx(R, abs=1e-9)
            assert distance(p, wall) == pytest.approx(R, abs=1e-9)
            assert distance(p, shape) > R - 1e-6


def test_a_stop_the_judge_does_not_confirm_stays_a_stop():
    """Mid-stretch, away from the gap, every position past a stop is feasible: no split
    (the stop would stay partial, never hidden)."""
    p = part()
    i, j = FACTS["pair"]
    s1, s2, job = pair_job(p.face(i), p.face(j), radius=R, feed=1500.0, period=0.004)
    (edge,) = pair_stretches(s1, s2, job)
    (st,) = edge.stretches   # the search alone runs one stretch across the gap
    assert split_at_stop(edge, st, (14.0, 8.0, 11.0)) is None
    head, rest = split_at_stop(edge, st, (19.9, 8.0, 11.0))
    assert head.end.rule == "boundary" and len(rest) == 1
    assert head.end.p[0] == pytest.approx(19.9, abs=40e-6)
    assert rest[0].start.p[0] == pytest.approx(20.1, abs=40e-6)


def test_a_setup_part_keeps_its_coordinates_in_a_worker():
    """The blob a worker rebuilds the part from keeps the setup: the same turned shape,
    not turned a second time by the gate (before: the -Z program was refused as a 10 mm
    gouge with --jobs > 1)."""
    job = cadcnc.Job(cadcnc.Tool(R), 1500.0, 0.004, cadcnc.PairPath(), axis="-Z")
    sp = setup_part(part(), job)
    rebuilt = part_from_blob(*part_blob(sp))
    assert setup_in(rebuilt) is not None
    assert setup_part(rebuilt, job) is rebuilt
    for a, b in zip(rebuilt.bounding_box(), sp.bounding_box()):
        assert np.allclose(a, b, atol=1e-9)
    n = FACTS["pair"][0]
    uv = [0.5 * sum(sp.face(n).u_range), 0.5 * sum(sp.face(n).w_range)]
    assert np.allclose(rebuilt.face(n).point(*uv), sp.face(n).point(*uv), atol=1e-12)
