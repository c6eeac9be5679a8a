"""The APT-like part program: grammar, errors with line and column, execution."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc import apt
from cadcnc.errors import FacePairError, ProgramSyntaxError, StepFileError

from conftest import FIXTURES, load_fixture

GOOD = f"""$$ both saddle edges, then part of one at a higher feed
PARTNO/'saddle'
PART = '{FIXTURES / "crossing_cylinders.step"}'
cutter/R=3, C=0.1   $$ keywords are case-insensitive
FEED/1500
PERIOD/4ms
SADDLE1 = P/[F1, F2, EDGE, EDGE]
SADDLE2 = P/[F1, F2,
             EDGE(2), EDGE(2)]
CUTTER/R=3
FEDRAT/3000
PERIOD/250us
PART3 = P/[1, 2, EDGE, (5, 11.2, 22)]
FINI
"""


def test_parse_and_jobs():
    statements = apt.parse(GOOD, "good.apt")
    assert [s.keyword for s in statements] == [
        "PARTNO", "PART", "CUTTER", "FEED", "PERIOD", "PATH", "PATH", "CUTTER", "FEED",
        "PERIOD", "PATH", "FINI"]
    jobs = apt.jobs(statements, ".", "good.apt")
    assert [j.name for j in jobs] == ["SADDLE1", "SADDLE2", "PART3"]
    assert [j.line for j in jobs] == [7, 8, 13]
    j1, j2, j3 = jobs
    assert (j1.radius, j1.allowance, j1.feed, j1.period) == (3.0, 0.1, 1500.0, 0.004)
    assert j1.faces == (1, 2) and j1.edge == 0 and j2.edge == 1
    assert (j3.radius, j3.allowance, j3.feed) == (3.0, 0.0, 3000.0)
    assert j3.period == pytest.approx(250e-6)
    assert j3.end == (5.0, 11.2, 22.0) and j1.title == "saddle"


@pytest.mark.parametrize("text, line, column, message", [
    ("FEED/1500\nPERIOD/4\n", 2, 8, "no unit"),
    ("FEED/1500\nPERIOD/4min\n", 2, 8, "unknown period unit 'min'"),
    ("CUTTER/D=6\n", 1, 8, "expected R=radius or C=allowance"),
    ("CUTTER/C=1\n", 1, 1, "CUTTER needs R=radius"),
    ("A = P/[F4, F5, EDGE EDGE]\n", 1, 21, "expected ','"),
    ("A = P/[F4, F5, (1, 2), EDGE]\n", 1, 21, "after the y coordinate"),
    ("A = P/[F4, G5, EDGE, EDGE]\n", 1, 12, "expected face S2 as F<number>"),
    ("A = P/[F4, F5, EDGE, EDGE\n", 2, 1, "expected ']'"),
    ("PART = boss\n", 1, 8, "quoted string"),
    ("GOTO/1, 2, 3\n", 1, 1, "unknown statement 'GOTO'"),
    ("FEED/1500 # x\n", 1, 11, "unexpected character '#'"),
    ("FEED/0\n", 1, 6, "feed must be > 0"),
    ("FINI\nFEED/1\n", 2, 1, "statement after FINI"),
    ("FEED/1500 1500\n", 1, 11, "expected end of statement"),
])
def test_syntax_errors_name_line_and_column(text, line, column, message):
    with pytest.raises(ProgramSyntaxError, match=message) as info:
        apt.parse(text, "bad.apt")
    assert (info.value.line, info.value.column) == (line, column)
    assert str(info.value).startswith(f"bad.apt:{line}:{column}: ")


@pytest.mark.parametrize("text, message", [
    ("FEED/1\n", "no PATH"),
    ("CUTTER/R=3\nFEED/1500\nPERIOD/4ms\nA = P/[F4, F5, EDGE, EDGE]\n", "needs PART"),
    ("PART='x.step'\nFEED/1500\nPERIOD/4ms\nA = P/[F4, F5, EDGE, EDGE]\n", "needs CUTTER"),
    ("PART='x.step'\nCUTTER/R=3\nFEED/1\nPERIOD/4ms\nA = P/[F1, F2, EDGE(1), EDGE(2)]\n",
     "IS names EDGE\\(1\\) but IE names EDGE\\(2\\)"),
])
def test_missing_settings(text, message):
    with pytest.raises(ProgramSyntaxError, match=message):
        apt.jobs(apt.parse(text, "p.apt"), ".", "p.apt")


def test_check_names_the_path_line_before_computing(tmp_path):
    boss = FIXTURES / "bspline_boss.step"
    text = (f"PART = '{boss}'\nCUTTER/R=3\nFEED/1500\nPERIOD/4ms\n"
            "A = P/[F4, F5, EDGE, EDGE]\nB = P/[F5, F6, EDGE, EDGE]\n")
    jobs = apt.jobs(apt.parse(text, "p.apt"), ".", "p.apt")
    with pytest.raises(FacePairError, match=r"^p.apt:6: PATH B: .*convex edge"):
        apt.check(jobs, "p.apt")
    (tmp_path / "p.apt").write_text(text.replace(str(boss), "nope.step"))
    jobs, _ = apt.read_program(tmp_path / "p.apt")
    assert jobs[0].part_file == str(tmp_path / "nope.step")  # relative to the program
    with pytest.raises(StepFileError, match="p.apt:5: PATH A: .*nope.step: no such file"):
        apt.check(jobs, "p.apt")


def test_execution_matches_the_python_api():
    jobs = apt.jobs(apt.parse(GOOD, "good.apt"), ".", "good.apt")
    checked = apt.check(jobs, "good.apt", load=lambda f: load_fixture("crossing_cylinders"))
    part = load_fixture("crossing_cylinders")
    paths = [apt.run_job(j, p) for j, p in checked]
    direct = cadcnc.intersection_paths(part.face(1), part.face(2), radius=3.0,
                                       allowance=0.1, feed=1500.0, period=0.004)
    for got, want in zip(paths[:2], direct):
        np.testing.assert_array_equal(got.points, want.points)
    # a lone EDGE end becomes the shared edge's start point
    edge = part.shared_edges(1, 2)[0]
    assert checked[2][0].start == pytest.approx(tuple(edge.start))
    assert paths[2].stop_reason == "end"


def test_stream_increments_sum_to_the_path():
    jobs = apt.jobs(apt.parse(GOOD, "good.apt"), ".", "good.apt")
    (job, part), = apt.check(jobs[:1], "good.apt",
                             load=lambda f: load_fixture("crossing_cylinders"))
    stepper, increments = apt.stream_job(job, part)
    start = np.array(stepper.p)
    dps = np.array(list(increments))
    path = apt.run_job(job, part)
    assert len(dps) == len(path) - 1
    np.testing.assert_allclose(start + np.cumsum(dps, axis=0), path.points[1:], atol=1e-12)
    assert np.allclose(np.linalg.norm(dps[:-1], axis=1), 0.1, rtol=1e-3)
