"""``cadcnc finish --axis`` (issue 23): the +X pocket's floor of fixtures/six_pockets.step,
finished from its own side.

The floor faces +X, so only a tool along +X reaches it. Its G-code is read by rs274 and
mapped back through the transform its own comments state. Every cut point then lies R
from the floor (OCCT's distance), on the floor's offset plane (closed form), and every
move, links included, keeps the ball and a shank along +X clear of the part (OCCT's
BRepExtrema, not cadcnc's guard). The JSON stays in part coordinates.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from cadcnc.testing.rs274 import RS274
from cadcnc.testing.rs274 import moves as rs274_moves
from helpers.cli import cadcnc_cli
from helpers.six_pockets import (
    AXES,
    DIGITS,
    FACTS,
    GOUGE,
    SHANK,
    STEP,
    R,
    distance,
    face_distance,
    written_transform,
)

pytestmark = pytest.mark.slow  # about 48 s of CPU: a quarter of the fast tier

SIDE = "+X"
FLOOR_AT = 15.0   # mm: the pockets' floors lie 15 mm from the cube's centre (the builder)


@pytest.mark.skipif(RS274 is None, reason="LinuxCNC rs274 not installed")
def test_finish_along_x_lies_on_the_floor_offset_and_keeps_the_shank_clear(tmp_path):
    import cadcnc
    from cadcnc.io.program_json import read_program

    part = cadcnc.load_step(STEP)
    floor = FACTS["sides"][SIDE]["floor"]
    d = np.array(AXES[SIDE], float)
    out = [tmp_path / "f.ngc", tmp_path / "f.json"]
    run = cadcnc_cli("finish", STEP, "--faces", floor, "--radius", R, "--stepover", 2,
                     "--axis", SIDE, "--jobs", 1, *[a for o in out for a in ("-o", o)],
                     check=0)
    assert f"tool axis {SIDE}" in run.stdout
    data = json.loads(out[1].read_text())                      # JSON: part coordinates
    assert data["setup"]["axis"] == list(d)
    cuts = np.vstack([s["points"] for s in data["segments"] if s["kind"] == "cut"])
    assert len(cuts) > 100
    assert np.allclose(cuts @ d, FLOOR_AT + R, atol=1e-9)      # the floor's offset plane
    for p in cuts[::25]:
        assert abs(face_distance(part, floor, p) - R) <= 1e-6, p
    ngc = out[0].read_text()
    rot, zero = written_transform(ngc)
    assert np.allclose(rot @ d, [0, 0, 1])                     # the axis is the machine's +Z
    moves = rs274_moves(out[0])
    pts = np.array([p for _, p in moves]) @ rot + zero         # back to part coordinates
    feeds = pts[[k for k, (kind, _) in enumerate(moves) if kind == "STRAIGHT_FEED"
                 and abs(pts[k] @ d - (FLOOR_AT + R)) < DIGITS]]
    # the written cuts are the program's: each JSON cut point has a G-code point near it
    # (the straight floor passes keep only their ends, so compare the ends)
    ends = np.vstack([(s["points"][0], s["points"][-1]) for s in data["segments"]
                      if s["kind"] == "cut"])
    assert np.abs(ends[:, None, :] - feeds[None, :, :]).max(axis=2).min(axis=1).max() \
        <= DIGITS
    back = read_program(out[1])   # read back into its work coordinates, as the G-code
    assert back.job.axis == tuple(d)
    # the first move starts at the machine's home, not a point of the program
    for a, b in zip(pts[1:-1], pts[2:]):
        n = max(int(np.ceil(np.linalg.norm(b - a) / 1.0)), 1)
        for t in np.linspace(0.0, 1.0, n + 1):
            p = a + t * (b - a)
            assert distance(part.shape, p) >= R - GOUGE, p
            assert distance(part.shape, p, p + SHANK * d) >= R - GOUGE, p
