"""Property-based fuzz of the gate (issue 9): an accepted path never gouges.

Hypothesis draws a fixture pair, a ball radius, a feed, a period, a start point near the
pair's edge (up to 0.3 mm off it) and the point-dropping tolerance of the G-code. A path
is *accepted* when it is complete and :func:`gouge_gate` passes it on the moves actually
written (``programmed_moves`` of the G-code: dropping, rounding and links included).

The oracle is OCCT's distance from a point to each face (``BRepExtrema_DistShapeShape``)
and OCCT's solid classifier, at every written centre and every move's midpoint: the ball
of radius R' there must reach no deeper than λ into the solid. The fuzz was
how the issue found chords 1.8-15.9 um deep in 4 of 40 accepted paths; the examples are
derandomized (seeded), so a failure reproduces. LinuxCNC's rs274 must read the G-code of
every accepted path without an error.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import cadcnc
from cadcnc.core.errors import CadcncError
from cadcnc.io.gcode import programmed_moves
from cadcnc.io.program_gcode import to_ngc
from cadcnc.ops.path.pair_path import intersection_path
from cadcnc.testing.moves_judge import polyline_depths
from cadcnc.testing.rs274 import feed_points
from cadcnc.verification import gouge_gate
from helpers.fixtures import FIXTURES, load_fixture

pytestmark = pytest.mark.slow  # over about 5 s a test (pyproject.toml)

# (part, face i, face j, smallest and largest ball radius in mm)
PAIRS = [
    ("bspline_boss", 4, 5, 1.0, 6.0),
    ("sphere_cylinder", 1, 2, 1.0, 8.0),
    ("torus_cone", 1, 2, 2.0, 8.0),
    ("step_block.step", 3, 8, 1.0, 5.0),
    ("thin_ring.step", 3, 7, 1.0, 4.0),
]
_parts: dict = {}
ACCEPTED: list = []   # (pair, radius, worst oracle depth): what the fuzz saw accepted
SEEN: list = []       # every draw: (part, radius, step, outcome)


def part_of(name: str):
    if name not in _parts:
        _parts[name] = (cadcnc.load_step(FIXTURES / name) if name.endswith(".step")
                        else load_fixture(name))
    return _parts[name]


def edge_start(part, i, j, t: float, offset) -> np.ndarray:
    """A sample point at fraction ``t`` of the pair's shared concave edge (of its
    classification samples), moved by ``offset`` (mm, (3,))."""
    edge = next(e for e in part.shared_edges(i, j) if e.edge_class == "concave")
    pts = edge.points
    return pts[min(int(t * len(pts)), len(pts) - 1)] + np.asarray(offset)


@settings(max_examples=10, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(pair=st.sampled_from(PAIRS), r=st.floats(0.0, 1.0), step=st.floats(0.4, 1.5),
       period=st.sampled_from([0.001, 0.004, 0.008]),
       start=st.one_of(st.none(), st.tuples(st.floats(0.05, 0.95),
                                            st.lists(st.floats(-0.3, 0.3), min_size=3,
                                                     max_size=3))),
       drop=st.sampled_from([None, 0.0005, 0.002]))
def test_an_accepted_path_never_gouges_along_its_moves(pair, r, step, period, start, drop):
    name, i, j, rmin, rmax = pair
    part = part_of(name)
    radius = rmin + r * (rmax - rmin)
    feed = 60.0 * step / period   # mm/min for a step of ``step`` mm
    kw = dict(radius=radius, feed=feed, period=period)
    if start is not None:
        kw["start"] = tuple(edge_start(part, i, j, start[0], start[1]))
    try:
        tp = intersection_path(part.face(i), part.face(j), **kw)
    except CadcncError as e:
        SEEN.append((name, radius, step, f"refused: {e}"[:60]))
        return   # refused up front with a reason: nothing is written
    if not tp.complete:
        SEEN.append((name, radius, step, "partial"))
        return   # exit 6: not accepted
    text = to_ngc([tp], tolerance=drop)
    moves = programmed_moves(text)
    gate = gouge_gate(tp, part, moves=moves)
    if not gate.ok:
        SEEN.append((name, radius, step, "gouge"))
        return   # exit 5: not accepted
    ball, limit = tp.job.tool.offset, tp.job.tolerances.gouge
    # centres and midpoints interleaved: one polyline through both
    dense = np.empty((2 * len(moves) - 1, 3))
    dense[0::2], dense[1::2] = moves, 0.5 * (moves[1:] + moves[:-1])
    worst = float(polyline_depths(part, dense, ball).max())
    if shutil.which("rs274"):   # LinuxCNC's interpreter reads every file we would write
        with tempfile.TemporaryDirectory() as tmp:
            assert len(feed_points(Path(tmp), text)) > 0
    ACCEPTED.append((pair, radius, worst))
    SEEN.append((name, radius, step, f"accepted, worst {worst:.2e} mm"))
    assert worst <= limit, (pair, kw, drop, worst)


def test_the_fuzz_accepts_some_paths():
    """The property above is not vacuous: run after it, some draws were accepted."""
    if not SEEN:
        pytest.skip("run with the fuzz")
    print("\n".join(map(str, SEEN)))
    assert len(ACCEPTED) >= 3
