"""Every command as a user runs it, in-process through ``main(argv)``.

Outputs are parsed and compared with the Python API; error cases check the documented
one-line messages and exit codes (docs/reliability.md "Exit codes"). Expensive runs are
module-scoped. The console script itself is exercised by the subprocess smoke tests in
test_cli_smoke.py.
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from cadcnc.cli.app import main
from cadcnc.core.errors import StepFileError
from cadcnc.io import read_csv, read_json
from cadcnc.ops.path.pair_path import intersection_path
from helpers.cli import cadcnc_cli, in_folder
from helpers.fixtures import FIXTURES, fixture_path, load_fixture

BOSS = str(FIXTURES / "bspline_boss.step")
SADDLE = str(FIXTURES / "crossing_cylinders.step")
POCKET = str(FIXTURES / "pocket.step")
JOB = ["--radius", "3", "--feed", "1500", "--period", "4ms"]


# -- help and faces ----------------------------------------------------------------------------
def test_help_lists_commands_and_units():
    run = cadcnc_cli("--help", check=0)
    for name in ("faces", "path", "run", "demo", "plot", "verify"):
        assert name in run.stdout
    sub = " ".join(cadcnc_cli("path", "--help", check=0).stdout.split())
    assert "mm/min" in sub and "4ms, 0.004s or 250us" in sub and "ball radius, mm" in sub


def test_faces_text_names_the_concave_pairs():
    run = cadcnc_cli("faces", BOSS, check=0)
    assert "8 faces" in run.stdout
    assert "concave pairs" in run.stdout and "4 5" in run.stdout
    assert "5 concave 259.0..277.2" in run.stdout


def test_faces_json_agrees_with_the_part():
    data = json.loads(cadcnc_cli("faces", POCKET, "--json", check=0).stdout)
    part = load_fixture("pocket")
    assert data["n_faces"] == len(part) == len(data["faces"])
    assert [tuple(p) for p in data["concave_pairs"]] == part.concave_pairs()
    f17 = data["faces"][16]
    assert f17["number"] == 17 and f17["kind"] == "plane"
    assert f17["area_mm2"] == pytest.approx(part.face(17).area(), rel=1e-6)
    assert {n["face"]: n["class"] for n in f17["neighbours"]} == {
        m: part.pair_class(17, m) for m in part.neighbours(17)}


# -- path --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def boss_outputs(boss_cli_outputs):
    """``cadcnc path`` BOSS 4 5 with JOB to p.json, p.csv and p.ngc (conftest: run once)."""
    return boss_cli_outputs


@pytest.fixture(scope="module")
def boss_api():
    return fixture_path("bspline_boss", 4, 5)


def test_path_summary(boss_outputs, boss_api):
    _, run = boss_outputs
    out = run.stdout
    assert (f"cut 1: faces 4 5, edge 1, stretch 1: {boss_api.length:.4f} mm, "
            f"{len(boss_api)} points, {boss_api.duration:.4f} s") in out
    assert "stop closed" in out and "eq. 16" in out and "wrote" in out
    assert "result     complete" in out
    # nothing on stderr but the gate's progress (printed when it runs over a second)
    assert all(line.startswith("cadcnc: path: gouge check: ")
               for line in run.stderr.splitlines()), run.stderr


def test_path_json_agrees_with_the_api(boss_outputs, boss_api):
    d, _ = boss_outputs
    tp = read_json(d / "p.json")
    np.testing.assert_array_equal(tp.points, boss_api.points)
    np.testing.assert_array_equal(tp.uv, boss_api.uv)
    np.testing.assert_array_equal(tp.bounds[1].eq16, boss_api.bounds[1].eq16)
    assert tp.job.period == 0.004 and tp.job.feed == 1500.0
    assert tp.faces == (4, 5) and tp.stop_reason == boss_api.stop_reason


def test_path_csv_agrees_with_the_api(boss_outputs, boss_api):
    d, _ = boss_outputs
    cols = read_csv(d / "p.csv")
    np.testing.assert_array_equal(np.column_stack([cols["x"], cols["y"], cols["z"]]),
                                  boss_api.points)


@pytest.mark.skipif(shutil.which("rs274") is None, reason="LinuxCNC rs274 not installed")
def test_path_ngc_through_rs274(boss_outputs, boss_api, tmp_path):
    from cadcnc.testing.rs274 import feed_points

    d, _ = boss_outputs
    text = (d / "p.ngc").read_text()
    feeds = feed_points(tmp_path, text)
    np.testing.assert_allclose(feeds, boss_api.points, rtol=0, atol=0.5e-4 + 1e-9)
    # rapids at the part's top (z 45) plus 10 mm
    assert "G0 Z55\n" in text


@pytest.mark.parametrize("args, code, message", [
    (["faces", "nope.step"], 2, "nope.step: no such file"),
    (["faces", FIXTURES / "README.md"], 2, "not a STEP file"),
    (["path", POCKET, "--faces", "17", "99", *JOB, "-o", "x.json"], 2,
     "face number 99 out of range: the part has faces 1..17"),
    (["path", POCKET, "--faces", "1", "17", *JOB, "-o", "x.json"], 2,
     "faces 1 and 17 are not adjacent"),
    (["path", BOSS, "--faces", "5", "6", *JOB, "-o", "x.json"], 2,
     "faces 5 and 6 meet along a convex edge"),
    (["path", BOSS, "--faces", "4", "5", "--radius", "3", "--feed", "1500", "--period", "4",
      "-o", "x.json"], 2, "period: '4' has no unit; give a unit: 4ms, 0.004s or 250us"),
    (["path", BOSS, "--faces", "4", "5", "--radius", "3", "--feed", "1500", "--period",
      "4min", "-o", "x.json"], 2, "period: unknown unit 'min'"),
    (["path", BOSS, "--faces", "4", "5", *JOB, "-o", "x.txt"], 4, "unknown output format"),
    (["path", BOSS, "--faces", "4", "5", *JOB, "-o", "nodir/x.json"], 4, "does not exist"),
    (["path", BOSS, "--faces", "4", "5", "--radius", "3mm", "--feed", "1500",
      "--period", "4ms", "--allowance", "1in", "-o", "x.json"], 2, "lengths are in mm"),
])
def test_errors_are_one_line_with_exit_codes(tmp_path, args, code, message):
    run = cadcnc_cli(*args, cwd=tmp_path)
    assert run.returncode == code, run.stderr
    assert run.stderr.startswith("cadcnc: error: ") and message in run.stderr
    assert "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []  # nothing half-written


def test_debug_raises_instead_of_one_line(tmp_path):
    with in_folder(tmp_path), pytest.raises(StepFileError, match="nope.step"):
        main(["faces", "nope.step", "--debug"])


# -- run ---------------------------------------------------------------------------------------
PROGRAM = f"""$$ the boss, then both saddle edges
PARTNO/'cli test'
PART = '{BOSS}'
CUTTER/R=3
FEED/1500
PERIOD/4ms
BOSS = P/[F4, F5, EDGE, EDGE]
PART = '{SADDLE}'
SADDLE = P/[F1, F2, EDGE(2), EDGE(2)]
FINI
"""


@pytest.fixture(scope="module")
def program_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    (d / "job.apt").write_text(PROGRAM)
    run = cadcnc_cli("run", "job.apt", "-o", "job.ngc", "-o", "job.json", cwd=d, check=0)
    return d, run


def test_run_writes_every_path(program_run, boss_api):
    d, run = program_run
    assert "PATH BOSS (line 7)" in run.stdout and "PATH SADDLE (line 9)" in run.stdout
    boss = read_json(d / "job-BOSS.json")
    np.testing.assert_array_equal(boss.points, boss_api.points)
    saddle = read_json(d / "job-SADDLE.json")
    part = load_fixture("crossing_cylinders")
    want = intersection_path(part.face(1), part.face(2), radius=3.0, feed=1500.0,
                                    period=0.004, edge=1)
    np.testing.assert_array_equal(saddle.points, want.points)


@pytest.mark.skipif(shutil.which("rs274") is None, reason="LinuxCNC rs274 not installed")
def test_run_ngc_through_rs274(program_run, tmp_path):
    from cadcnc.testing.rs274 import feed_points

    d, _ = program_run
    feeds = feed_points(tmp_path, (d / "job.ngc").read_text())
    expected = np.vstack([read_json(d / f"job-{n}.json").points for n in ("BOSS", "SADDLE")])
    np.testing.assert_allclose(feeds, expected, rtol=0, atol=0.5e-4 + 1e-9)


def test_run_stream(tmp_path, boss_api):
    (tmp_path / "boss.apt").write_text(PROGRAM.split("PART = '" + SADDLE)[0] + "FINI\n")
    run = cadcnc_cli("run", "boss.apt", "--stream", cwd=tmp_path, check=0)
    lines = run.stdout.splitlines()
    assert lines[0].startswith("# PATH BOSS: faces 4 5") and lines[-1].startswith("# stop")
    start = np.array(lines[0].split("start ")[1].split(), dtype=float)
    dps = np.array([ln.split() for ln in lines[1:-1]], dtype=float)
    assert len(dps) == len(boss_api) - 1
    np.testing.assert_allclose(start + np.cumsum(dps, axis=0), boss_api.points[1:], atol=1e-6)


def test_run_syntax_error_names_line_and_column(tmp_path):
    (tmp_path / "bad.apt").write_text(PROGRAM.replace("EDGE(2), EDGE(2)", "EDGE(2) EDGE(2)"))
    run = cadcnc_cli("run", "bad.apt", cwd=tmp_path)
    assert run.returncode == 2
    assert run.stderr.strip() == ("cadcnc: error: bad.apt:9:29: expected ',' then IE (end: a "
                                  "point (x, y, z) or EDGE), found 'EDGE'")


def test_run_bad_pair_before_computing(tmp_path):
    (tmp_path / "bad.apt").write_text(PROGRAM.replace("F1, F2", "F1, F3"))
    run = cadcnc_cli("run", "bad.apt", "-o", "x.ngc", cwd=tmp_path)
    assert run.returncode == 2 and run.stdout == ""  # not even the first path ran
    assert "bad.apt:9: PATH SADDLE:" in run.stderr and "convex edge" in run.stderr
    assert not (tmp_path / "x.ngc").exists()


# -- demo, plot, verify ------------------------------------------------------------------------
@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("demo")
    run = cadcnc_cli("demo", "--out", d / "out", check=0)
    return d / "out", run


def test_demo_writes_everything(demo_run, boss_api):
    out, run = demo_run
    names = {p.name for p in out.iterdir()}
    assert {"path.json", "path.csv", "path.ngc", "path.png", "demo.apt", "pencil.json",
            "pencil.png"} <= names
    from cadcnc.io.program_json import read_program

    pen = read_program(out / "pencil.json")
    assert len(pen.cuts) == 1 and pen.complete and "pencil R 3: 1 cuts" in run.stdout
    assert f"wrote {out}/" in run.stdout
    np.testing.assert_array_equal(read_json(out / "path.json").points, boss_api.points)
    assert (out / "path.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert {"verification.txt", "verification.json"} <= names
    data = json.loads((out / "verification.json").read_text())
    assert data["max_overcut_mm"] < 1e-3 and "verified" in run.stdout


def test_demo_program_runs(demo_run, boss_api, tmp_path):
    out, _ = demo_run
    run = cadcnc_cli("run", out / "demo.apt", "-o", tmp_path / "demo.json", "--quiet",
                     check=0)
    assert run.stdout == ""
    np.testing.assert_array_equal(read_json(tmp_path / "demo.json").points, boss_api.points)


@pytest.mark.parametrize("suffix, magic", [(".png", b"\x89PNG"), (".glb", b"glTF")])
def test_plot(boss_outputs, tmp_path, suffix, magic):
    d, _ = boss_outputs
    out = tmp_path / f"pic{suffix}"
    run = cadcnc_cli("plot", d / "p.json", "--part", BOSS, "-o", out, check=0)
    assert out.read_bytes()[:4] == magic and f"wrote {out}" in run.stdout
    if suffix == ".glb":
        import trimesh

        scene = trimesh.load(out)
        # the program: approach link, the cut, retract; the part's faces
        assert {"link1", "cut2", "link3", "face4", "face5"} <= set(scene.geometry)


def test_plot_bad_suffix(boss_outputs, tmp_path):
    d, _ = boss_outputs
    run = cadcnc_cli("plot", d / "p.json", "-o", tmp_path / "pic.svg")
    assert run.returncode == 4 and "unknown picture format '.svg'" in run.stderr


def test_verify_computed_path_json():
    """A program of one cut: the report keeps the version 1 keys."""
    run = cadcnc_cli("verify", BOSS, "--faces", "4", "5", *JOB, "--json", check=0)
    data = json.loads(run.stdout)
    for key in ("max_overcut_mm", "max_undercut_mm", "hausdorff_mm", "coverage",
                "whole_part_hits"):
        assert key in data
    assert data["max_overcut_mm"] < 1e-3 and data["coverage"] > 0.99


def test_verify_saved_path_and_gate(boss_outputs):
    d, _ = boss_outputs
    ok = cadcnc_cli("verify", d / "p.json", "--part", BOSS, check=0)
    assert "over-cut" in ok.stdout
    strict = cadcnc_cli("verify", d / "p.json", "--gouge-tolerance", "1e-9", "--quiet")
    assert strict.returncode == 5
    assert strict.stderr.startswith("cadcnc: verify: failed gouge") and "limit 1e-09" in strict.stderr


def test_verify_needs_the_job_parameters():
    run = cadcnc_cli("verify", BOSS, "--faces", "4", "5")
    assert run.returncode == 2 and "needs --radius" in run.stderr
    assert "--feed" not in run.stderr   # feed and period default to 1500 mm/min, 4 ms


@pytest.mark.parametrize("example", ["boss.apt", "saddle.apt"])
def test_docs_examples_run(example, tmp_path):
    """The programs in docs/examples run and their G-code reads in rs274."""
    program = FIXTURES.parent / "docs" / "examples" / example
    out = tmp_path / "prog.ngc"
    cadcnc_cli("run", program, "-o", out, "--tool-tip", "--quiet", check=0)
    if shutil.which("rs274") is not None:
        from cadcnc.testing.rs274 import feed_points

        assert len(feed_points(tmp_path, out.read_text())) > 400


def test_path_refuses_a_pair_with_no_feasible_position(tmp_path):
    """A 3 mm ball in the 4 mm slot would cut the opposite wall everywhere: the pair is
    refused up front (exit 3: valid input, no program), with the reason per edge: the
    third face in the way; nothing written, --allow-gouge changes nothing."""
    out = tmp_path / "slot.json"
    args = ["path", FIXTURES / "narrow_slot.step", "--faces", "3", "4", *JOB, "-o", out]
    for extra in ([], ["--allow-gouge", "--allow-partial"]):
        run = cadcnc_cli(*args, *extra)
        assert run.returncode == 3 and run.stderr.startswith("cadcnc: error: ")
        assert len(run.stderr.strip().splitlines()) == 1
        assert "no feasible ball position" in run.stderr and "edge 1:" in run.stderr and "third face" in run.stderr
        assert "face 6 (2 mm too near)" in run.stderr
        assert not out.exists()


def test_verify_old_tolerance_spelling_still_gates(boss_outputs):
    """``--tolerance`` parses into the very options ``--gouge-tolerance`` gives, and
    ``main`` acts on nothing else: the strict gate that test_verify_saved_path_and_gate
    runs (exit 5, "limit 1e-09") is this spelling's too, without a second 5 s gate."""
    from cadcnc.cli.app import build_parser

    d, _ = boss_outputs
    old, new = (vars(build_parser().parse_args(["verify", str(d / "p.json"), flag, "1e-9",
                                                 "--quiet"]))
                for flag in ("--tolerance", "--gouge-tolerance"))
    assert old == new and old["gouge_tolerance"] == "1e-9"


def test_safe_z_is_an_alias_of_clearance(tmp_path):
    """The pocket's straight edge (a program in 0.2 s): any part shows the alias."""
    for flag in ("--clearance", "--safe-z"):
        out = tmp_path / f"{flag[2:]}.ngc"
        cadcnc_cli("path", POCKET, "--faces", "10", "17", *JOB, "-o", out, flag, "80",
                   "--quiet", check=0)
        assert "G0 Z80\n" in out.read_text()
