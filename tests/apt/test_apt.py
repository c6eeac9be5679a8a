"""The APT-like part program: grammar, errors with line and column, execution."""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc import apt
from cadcnc.core.errors import FacePairError, InputError, ProgramSyntaxError, StepFileError
from cadcnc.core.job import Job
from cadcnc.core.tolerances import DEFAULT, Tolerances
from helpers.fixtures import FIXTURES, fixture_path, load_fixture

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
SETTINGS = "PART='x.step'\nCUTTER/R=3\nFEED/1500\nPERIOD/4ms\n"


def cylinders(_file):
    return load_fixture("crossing_cylinders")


@pytest.fixture(scope="module")
def good():
    return apt.entries(apt.parse(GOOD, "good.apt"), ".", "good.apt")


@pytest.fixture(scope="module")
def checked(good):
    return apt.check(good, "good.apt", load=cylinders)


@pytest.fixture(scope="module")
def program_paths(checked):
    return [apt.run_job(entry, part) for entry, part in checked]


def test_parse_and_entries(good):
    statements = apt.parse(GOOD, "good.apt")
    assert [s.keyword for s in statements] == [
        "PARTNO", "PART", "CUTTER", "FEED", "PERIOD", "PATH", "PATH", "CUTTER", "FEED",
        "PERIOD", "PATH", "FINI"]
    assert apt.title(statements) == "saddle"
    assert [e.name for e in good] == ["SADDLE1", "SADDLE2", "PART3"]
    assert [e.line for e in good] == [7, 8, 13]
    assert all(isinstance(e.job, Job) and e.job.tolerances is DEFAULT for e in good)
    j1, j2, j3 = (e.job for e in good)
    assert j1.source == str(FIXTURES / "crossing_cylinders.step")
    assert (j1.tool.radius, j1.tool.allowance, j1.feed, j1.period) == (3.0, 0.1, 1500.0, 0.004)
    assert j1.operation.faces == (1, 2) and j1.operation.edge == 0 and j2.operation.edge == 1
    assert j1.operation.start is None and good[0].pending is None  # EDGE, EDGE: the default
    assert (j3.tool.radius, j3.tool.allowance, j3.feed) == (3.0, 0.0, 3000.0)
    assert j3.period == pytest.approx(250e-6)
    # one EDGE end: the ends wait in `pending` until check() knows the edge
    assert j3.operation.start is None and good[2].pending[1].point == (5.0, 11.2, 22.0)
    assert good[2].pending[0].edge == 1


def test_program_options_go_into_every_job():
    tol = Tolerances(gouge=0.01)
    got = apt.entries(apt.parse(SETTINGS + "A = P/[F1, F2, EDGE, EDGE]\n"), tolerances=tol,
                      clearance=40)
    assert got[0].job.tolerances is tol and got[0].job.clearance == 40.0
    with pytest.raises(InputError, match="^clearance must be a finite height") as info:
        apt.entries(apt.parse(SETTINGS + "A = P/[F1, F2, EDGE, EDGE]\n"),
                    clearance=float("inf"))
    assert not isinstance(info.value, ProgramSyntaxError)  # not the program's fault


@pytest.mark.parametrize("text, line, column, message", [
    ("FEED/1500\nPERIOD/4\n", 2, 8, "no unit"),
    ("FEED/1500\nPERIOD/4min\n", 2, 8, "unknown period unit 'min'"),
    ("CUTTER/D=6\n", 1, 8, "expected R=radius or C=allowance"),
    ("CUTTER/C=1\n", 1, 1, "CUTTER needs R=radius"),
    ("A = P/[F4, F5, EDGE EDGE]\n", 1, 21, "expected ','"),
    ("A = P/[F4, F5, (1, 2), EDGE]\n", 1, 21, "after the y coordinate"),
    ("A = P/[F4, G5, EDGE, EDGE]\n", 1, 12, "expected face S2 as F<number>"),
    ("A = P/[F4, F5, EDGE, EDGE\n", 2, 1, "expected ']'"),
    ("A = P/[F4, F5, EDGE(0), EDGE]\n", 1, 21, "edge number must be an integer >= 1"),
    ("PART = boss\n", 1, 8, "quoted string"),
    ("GOTO/1, 2, 3\n", 1, 1, "unknown statement 'GOTO'"),
    ("FEED/1500 # x\n", 1, 11, "unexpected character '#'"),
    ("FINI\nFEED/1\n", 2, 1, "statement after FINI"),
    ("FEED/1500 1500\n", 1, 11, "expected end of statement"),
])
def test_syntax_errors_name_line_and_column(text, line, column, message):
    with pytest.raises(ProgramSyntaxError, match=message) as info:
        apt.parse(text, "bad.apt")
    assert (info.value.line, info.value.column) == (line, column)
    assert str(info.value).startswith(f"bad.apt:{line}:{column}: ")


@pytest.mark.parametrize("text, line, column, message", [
    ("FEED/0\n", 1, 6, "feed must be a number > 0 mm/min, got 0"),
    ("FEED/1500\nPERIOD/0ms\n", 2, 8, "period must be a number > 0 s, got 0"),
    ("CUTTER/R=-3\n", 1, 10, "radius must be a number >= 0 mm, got -3"),
    ("CUTTER/R=3, C=-0.5\n", 1, 15, "allowance must be a number >= 0 mm, got -0.5"),
    (SETTINGS + "A = P/[F0, F2, EDGE, EDGE]\n", 5, 8, "face numbers are integers from 1"),
    (SETTINGS + "A = P/[F1, F2, (1, 2, 1e999), EDGE]\n", 5, 16, "start must be a point"),
    (SETTINGS + "A = P/[F1, F2, EDGE, (1, 2, 1e999)]\n", 5, 22, "end must be a point"),
])
def test_values_the_job_refuses_name_line_and_column(text, line, column, message):
    statements = apt.parse(text, "bad.apt")  # syntax is fine
    with pytest.raises(ProgramSyntaxError, match=message) as info:
        apt.entries(statements, ".", "bad.apt")
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
        apt.entries(apt.parse(text, "p.apt"), ".", "p.apt")


def test_check_names_the_path_line_before_computing(tmp_path):
    boss = FIXTURES / "bspline_boss.step"
    text = (f"PART = '{boss}'\nCUTTER/R=3\nFEED/1500\nPERIOD/4ms\n"
            "A = P/[F4, F5, EDGE, EDGE]\nB = P/[F5, F6, EDGE, EDGE]\n")
    entries = apt.entries(apt.parse(text, "p.apt"), ".", "p.apt")
    with pytest.raises(FacePairError, match=r"^p.apt:6: PATH B: .*convex edge"):
        apt.check(entries, "p.apt", load=lambda f: load_fixture("bspline_boss"))
    (tmp_path / "p.apt").write_text(text.replace(str(boss), "nope.step"))
    entries, title = apt.read_program(tmp_path / "p.apt")
    assert entries[0].job.source == str(tmp_path / "nope.step")  # relative to the program
    assert title == ""
    with pytest.raises(StepFileError, match="p.apt:5: PATH A: .*nope.step: no such file"):
        apt.check(entries, "p.apt")


def test_execution_matches_the_python_api(checked, program_paths):
    part = load_fixture("crossing_cylinders")
    assert sum(e.edge_class == "concave" for e in part.shared_edges(1, 2)) == 2
    for k, got in enumerate(program_paths[:2]):
        want = fixture_path("crossing_cylinders", 1, 2, allowance=0.1, edge=k)
        np.testing.assert_array_equal(got.points, want.points)
        assert got.job.source == str(FIXTURES / "crossing_cylinders.step")
    # a lone EDGE end becomes the shared edge's start point
    edge = part.shared_edges(1, 2)[0]
    entry = checked[2][0]
    assert entry.pending is None
    assert entry.job.operation.start == pytest.approx(tuple(edge.start))
    assert entry.job.operation.end == (5.0, 11.2, 22.0)
    assert program_paths[2].stop_reason == "end"


def test_an_unchecked_lone_edge_end_is_refused(good):
    with pytest.raises(InputError, match="good.apt:13: PATH PART3: .*check"):
        apt.run_job(good[2], load_fixture("crossing_cylinders"), source="good.apt")


def test_stream_increments_sum_to_the_path(checked, program_paths):
    entry, part = checked[0]
    stepper, increments = apt.stream_job(entry, part)
    start = np.array(stepper.p)
    dps = np.array(list(increments))
    path = program_paths[0]
    assert len(dps) == len(path) - 1
    np.testing.assert_allclose(start + np.cumsum(dps, axis=0), path.points[1:], atol=1e-12)
    assert np.allclose(np.linalg.norm(dps[:-1], axis=1), 0.1, rtol=1e-3)
