"""Issue 20 on pencil and path: no traceback for a ball of no size, a tiny ball judged (not
refused), degenerate edges and short stretches, work estimated and bounded up front,
progress at least every 5 s (fake clock), and "nothing to cut" as exit 3.

The parts are cut here with CadQuery (small L-parts like the public ones of the issue)."""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import EXIT_NOTHING, InputError, NothingToCutError
from cadcnc.core.job import Job, PairPath, Pencil, Tool
from cadcnc.core.tolerances import DEFAULT
from cadcnc.core.work_limits import HEARTBEAT_S, WorkLimitError
from cadcnc.ops.common import safe_height
from cadcnc.ops.path.feasibility import too_tight
from cadcnc.ops.path.pair_path import plan_path
from cadcnc.ops.path.pair_program import program_for_job, stretch_cuts
from cadcnc.ops.path.stretches import EdgeStretches, Limit, Stretch
from cadcnc.ops.pencil.pencil_program import pencil_program
from cadcnc.pipeline.exit_policy import judge, settle
from cadcnc.testing.moves_judge import polyline_depths

_parts: dict = {}


def l_part(length: float = 10.0, sliver: float | None = None):
    """An L: floor z 0..5 over x 0..20, wall x 0..8 up to z 10, ``length`` mm along y; its
    one concave corner (faces 3, 4) runs along y at x 8, z 5. ``sliver``: a strip of the
    floor that wide at y = length / 2 made its own face, so that the wall meets it along a
    concave edge ``sliver`` mm long."""
    key = (length, sliver)
    if key not in _parts:
        import cadquery as cq  # ~3 s: only the tests that build a part pay it

        a = cq.Workplane().box(20, length, 5, centered=False)
        b = cq.Workplane().box(8, length, 5, centered=False).translate((0, 0, 5))
        shape = a.union(b)
        if sliver is not None:
            c = cq.Workplane().box(12, sliver, 5, centered=False).translate(
                (8, length / 2, 0))
            shape = shape.union(c, clean=False)
        _parts[key] = cadcnc.Part.from_cadquery(shape)
    return _parts[key]


def pencil_job(radius, allowance=0.0, **kw):
    return Job(Tool(radius, allowance), 1500.0, 0.004, Pencil(**kw))


def corner_faces(part):
    (pair,) = [p for p, edges in part.adjacency.items()
               if any(e.edge_class == "concave" and e.length > 1 for e in edges)]
    return pair


# -- 1. a ball of no size -------------------------------------------------------------

@pytest.mark.parametrize("op", ["path", "pencil"])
def test_a_ball_of_no_size_is_an_input_error_not_a_traceback(op):
    part = l_part()
    operation = PairPath(faces=corner_faces(part)) if op == "path" else Pencil()
    with pytest.raises(InputError, match="radius: a ball of R' = R \\+ C = 0 mm"):
        cadcnc.run(part, Job(Tool(0.0), 1500.0, 0.004, operation))
    assert not too_tight(5.0, 0.0, DEFAULT)   # a point follows any curvature: no division


# -- 2. a tiny ball -------------------------------------------------------------------


def test_a_ball_smaller_than_the_gouge_limit_is_judged_not_refused():
    """R 0.001 mm = the gouge limit: the gate used to find every move unprovable ("every
    cut gouges"); a move that touches no face stays outside, so the program passes, and
    the oracle agrees at every written centre and along every move (10 points a move)."""
    part = l_part()
    job = pencil_job(0.001)
    program = pencil_program(part, job)
    program = settle(program, part, safe_height(part, job), 1e-3, "pencil")
    verdict = judge(program, part, "pencil")
    assert verdict.code == 0, verdict.messages
    lam = job.tolerances.gouge
    for cut in program.cuts:
        p = cut.points
        t = np.linspace(0.0, 1.0, 10, endpoint=False)[None, :, None]
        along = (p[:-1, None, :] * (1 - t) + p[1:, None, :] * t).reshape(-1, 3)
        assert polyline_depths(part, np.vstack([along, p[-1:]]), job.tool.offset).max() <= lam


# -- 3. degenerate edges and short stretches ------------------------------------------

def test_an_edge_shorter_than_the_gouge_limit_is_skipped_with_a_reason():
    part = l_part(sliver=0.0005)
    program = pencil_program(part, pencil_job(1.0))
    degenerate = [s for s in program.skipped if s.reason == "degenerate"]
    assert len(degenerate) == 1 and "shorter than the gouge limit" in degenerate[0].detail
    assert program.complete and len(program.cuts) == 2


def test_a_sliver_edge_is_cut_to_its_length_and_complete():
    """A 0.007 mm concave edge (a floor strip of its own): cut over its 0.007 mm, the
    program complete (was: stopped 8 mm further on, exit 6)."""
    part = l_part(sliver=0.007)
    program = pencil_program(part, pencil_job(1.0))
    assert program.complete, program.partial_reasons
    short = [c for c in program.cuts if c.path.length < 0.01]
    assert len(short) == 1 and short[0].path.length == pytest.approx(0.007, abs=1e-5)
    assert sum(c.path.length for c in program.cuts) == pytest.approx(10.0, abs=1e-4)


@pytest.mark.parametrize("length", [0.007, 0.15, 0.3])
def test_a_stretch_shorter_than_a_few_steps_lands_on_its_end(length):
    """The stepper lands on an end only after 2 steps: a stretch shorter than that on a
    corner that goes on used to be run past its end to the faces' boundary (8 mm)."""
    part = l_part()
    i, j = corner_faces(part)
    s1, s2 = part.face(i), part.face(j)
    job = Job(Tool(1.0), 1500.0, 0.004, PairPath(faces=(i, j)))
    y0 = 2.0
    plan = plan_path(s1, s2, replace(job, operation=PairPath(
        faces=(i, j), start=(9.0, y0, 6.0), end=(9.0, y0 + length, 6.0))))
    st = Stretch(0, Limit(plan.start, "boundary", "", 0.0),
                 Limit(plan.end, "boundary", "", length), plan.direction, length)
    cuts, skipped = stretch_cuts(s1, s2, job, [EdgeStretches(0, length, [st])], None)
    (cut,) = cuts
    assert cut.at_limit and cut.path.complete and skipped == []
    assert cut.path.length == pytest.approx(length, abs=1e-9)
    assert cut.path.job.feed == job.feed and len(cut.points) >= 4


# -- 4. work estimated and bounded up front -------------------------------------------

@pytest.mark.parametrize("radius, allowance", [(1e6, 0.0), (1.0, 1e6)])
def test_a_huge_ball_is_refused_before_any_search(radius, allowance):
    with pytest.raises(WorkLimitError) as err:
        pencil_program(l_part(), pencil_job(radius, allowance))
    msg = str(err.value)
    assert "ball positions, over the limit" in msg and "--radius or --allowance" in msg
    assert err.value.exit_code == 2


def test_a_huge_part_is_refused_up_front_with_the_estimate():
    """A 4e5 mm corner: refused before its search (the search alone: 1e6 positions), and
    on the cycle estimate (8e6 cycles, run twice at most) over the cycle limit."""
    part = l_part(length=4e5)
    with pytest.raises(WorkLimitError) as err:
        pencil_program(part, pencil_job(1.0))
    msg = str(err.value)
    assert "needs about 8e+06 interpolation cycles" in msg
    assert "--feed or --period" in msg and "--max-cycles" in msg
    with pytest.raises(WorkLimitError, match="needs about 1e\\+06 ball positions"):
        pencil_program(part, pencil_job(1.0), max_cycles=10**8)


def test_counted_cycles_stay_within_the_estimate():
    """The estimate counts every corner twice (a cut against ``side`` runs again from its
    other end): here the one cut is run twice, 202 cycles for 200 estimated."""
    work: dict = {}
    program = pencil_program(l_part(), pencil_job(1.0), work=work)
    assert program.complete
    assert work["cycles"] > 0 and work["samples"] > 0
    assert work["cycles"] <= 1.5 * work["cycles_estimate"]
    assert work["cycles_estimate"] <= 2.5 * work["cycles"]
    assert work["samples"] <= 1.5 * work["samples_estimate"]


# -- 5. never silent for more than 5 s -----------------------------------------------

def test_progress_comes_at_least_every_5_s_inside_a_corner():
    """A fake clock that moves 1 s at every reading: the stretch search of the one corner
    reports while it runs, and no two reports are more than 5 s (+ one reading) apart."""
    ticks = itertools.count()
    now = [0.0]

    def clock():
        now[0] = float(next(ticks))
        return now[0]

    seen = []
    pencil_program(l_part(), pencil_job(1.0), clock=clock,
                   progress=lambda done, total, what: seen.append((now[0], done, what)))
    inside = [s for s in seen if "stretch search" in s[2]]
    assert len(inside) >= 3 and all(done == 0 for _, done, _ in inside)
    times = [t for t, _, _ in seen]
    assert max(np.diff(times)) <= HEARTBEAT_S + 1.0
    assert seen[-1][1:] == (1, "faces 3 4")


# -- 6. nothing to cut is exit 3, a bad pair exit 2 -----------------------------------

def test_a_corner_with_no_feasible_position_is_nothing_to_cut():
    """A ball wider than the L's floor: no position anywhere (exit 3, valid input)."""
    part = l_part()
    job = Job(Tool(15.0), 1500.0, 0.004, PairPath(faces=corner_faces(part)))
    with pytest.raises(NothingToCutError, match="no feasible ball position") as err:
        program_for_job(part, job)
    assert err.value.exit_code == EXIT_NOTHING


def test_a_pair_that_is_not_a_corner_stays_an_input_error():
    part = l_part()
    convex = next(p for p, edges in part.adjacency.items()
                  if all(e.edge_class == "convex" for e in edges))
    with pytest.raises(InputError, match="a ball cannot sit in that corner") as err:
        program_for_job(part, Job(Tool(1.0), 1500.0, 0.004, PairPath(faces=convex)))
    assert err.value.exit_code == 2
