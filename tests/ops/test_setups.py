"""The fewest setups (issue 23): ``pencil --setups`` on a corner two axes share.

The part (built here with CadQuery): a floor z = 10 (x 20..40) meets a wall x = 20 between
end walls at y = 2 and y = 28; a roof x 20..40, y 0..10, z 18..20 hangs over the corner,
and a fence x 35..40, y 20..30 stands on the floor. With R = 3 (shank 30) the ball's
centre runs on x = 23, z = 13, y 5..25 (the end walls stop it), and in closed form:

- from +Z the shank (radius 3) meets the roof wherever y < 10 + 3: +Z reaches y 13..25;
- from +X it meets the fence wherever y > 20 - 3: +X reaches y 5..17;
- -X, -Z go into the material at once, +Y and -Y into the end walls.

So two setups are needed, +Z then +X (equal reach: +Z first), and the second cuts only
y 5..13 (plus --setup-overlap).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess

import numpy as np
import pytest

from cadcnc.core.job import Job, Pencil, Tool
from helpers.cli import cadcnc_cli

R = 3.0
SPACING = 0.5   # mm: the setups' positions along a corner (cadcnc.ops.pencil.fewest_setups)
RS274 = shutil.which("rs274")


def box(x0, y0, z0, x1, y1, z1):
    import cadquery as cq

    return cq.Workplane("XY").box(x1 - x0, y1 - y0, z1 - z0, centered=False).translate(
        (x0, y0, z0))


@pytest.fixture(scope="module")
def shared_corner(tmp_path_factory):
    """(part, floor, wall, STEP path) of the part of the module doc."""
    import cadquery as cq

    import cadcnc

    shape = (box(0, 0, 0, 40, 30, 10).union(box(0, 0, 10, 20, 30, 20))
             .union(box(20, 0, 10, 40, 2, 20)).union(box(20, 28, 10, 40, 30, 20))
             .union(box(20, 0, 18, 40, 10, 20)).union(box(35, 20, 10, 40, 30, 20)))
    step = tmp_path_factory.mktemp("setups") / "shared_corner.step"
    cq.exporters.export(shape, str(step))
    part = cadcnc.load_step(step)
    floor = wall = None
    for f in part.faces:
        u, w = sum(f.u_range) / 2, sum(f.w_range) / 2
        p, n = f.point(u, w), f.normal(u, w)
        if f.kind == "plane" and np.allclose(np.abs(n), [0, 0, 1]) and abs(p[2] - 10) < 1e-9 \
                and p[0] > 20:
            floor = f.number
        if f.kind == "plane" and np.allclose(np.abs(n), [1, 0, 0]) and abs(p[0] - 20) < 1e-9:
            wall = f.number
    assert floor and wall and part.pair_class(floor, wall) == "concave"
    return part, floor, wall, step


def cut_ys(program, setup) -> list[tuple[float, float]]:
    """The y range of each cut of a setup's program, part coordinates."""
    from cadcnc.program.transform import in_part_coordinates

    return [(float(c.points[:, 1].min()), float(c.points[:, 1].max()))
            for c in in_part_coordinates(program, setup).cuts]


@pytest.mark.parametrize("overlap", [0.0, 2.0])
def test_two_setups_share_the_corner(shared_corner, overlap):
    import cadcnc
    from cadcnc.ops.pencil.fewest_setups import pencil_setups

    part, floor, wall, _ = shared_corner
    job = Job(Tool(R), 1500.0, 0.004, Pencil([floor, wall]), source=part.source)
    result = pencil_setups(part, job, "auto", overlap)
    assert [r.setup.name for r in result.runs] == ["+Z", "+X"]
    assert result.subsets_checked == 6 + 15     # no single axis covers: every pair tried
    first, second = result.runs
    (a0, a1), = cut_ys(first.program, first.setup)
    assert a0 == pytest.approx(13.0, abs=SPACING) and a1 == pytest.approx(25.0, abs=1e-3)
    ys = cut_ys(second.program, second.setup)
    assert len(ys) == 1
    b0, b1 = ys[0]
    assert b0 == pytest.approx(5.0, abs=1e-3)
    # not cut again: the second stops where the first began, or laps ``overlap`` into it
    assert b1 == pytest.approx(a0 + overlap, abs=SPACING + 0.1)
    for r in result.runs:
        assert cadcnc.gate_program(r.program, r.part).ok
        for c in r.program.cuts:   # each cut in its setup's work coordinates: +Z is its axis
            assert np.allclose(r.setup.to_part(c.points)[:, [0, 2]], [23.0, 13.0], atol=1e-6)
    assert first.assigned + second.assigned == result.positions
    assert result.reach["+Z"] > 0 and result.reach["+X"] > 0
    assert result.reach["-X"] == result.reach["-Z"] == 0


@pytest.mark.skipif(RS274 is None, reason="LinuxCNC rs274 not installed")
def test_cli_writes_one_program_per_setup(shared_corner, tmp_path):
    _, floor, wall, step = shared_corner
    run = cadcnc_cli("pencil", step, "--radius", R, "--faces", floor, wall, "--setups",
                     "auto", "-o", tmp_path / "P.json", "-o", tmp_path / "P.ngc", check=0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["P+X.json", "P+X.ngc",
                                                          "P+Z.json", "P+Z.ngc"]
    assert re.search(r"setups\s+2 of 6 candidate axes", run.stdout)
    assert re.search(r"setup \+Z\s+1 cuts", run.stdout) and "setup +X" in run.stdout
    assert "optimal" in run.stdout
    for tag in ("+Z", "+X"):
        ngc = tmp_path / f"P{tag}.ngc"
        assert f"tool axis {tag}" in ngc.read_text() or tag == "+Z"
        proc = subprocess.run([RS274, "-g", str(ngc), str(tmp_path / "canon")],
                              capture_output=True, text=True, timeout=60,
                              env={**os.environ, "HOME": str(tmp_path)})   # own .tool.mmap
        assert proc.returncode == 0 and "PROGRAM_END" in (tmp_path / "canon").read_text()


def test_listed_setup_reaching_nothing_exits_3(shared_corner, tmp_path):
    _, floor, wall, step = shared_corner
    run = cadcnc_cli("pencil", step, "--radius", R, "--faces", floor, wall, "--setups",
                     "-Y,+Z", "-o", tmp_path / "P.json")
    assert run.returncode == 3, (run.stdout, run.stderr)
    assert "setup -Y reaches no corner position" in run.stderr
    assert not list(tmp_path.iterdir())   # one output set: nothing written


@pytest.mark.parametrize("bad", ["+Q", "", "auto,+Z", "0,0,1"])
def test_bad_setups_exit_2(shared_corner, tmp_path, bad):
    _, floor, wall, step = shared_corner
    run = cadcnc_cli("pencil", step, "--radius", R, "--setups", bad, "-o", tmp_path / "P.json")
    assert run.returncode == 2 and "setups" in run.stderr, (run.stdout, run.stderr)


def test_worst_exit_code():
    from cadcnc.core.errors import EXIT_GOUGE, EXIT_NOTHING, EXIT_OK, EXIT_PARTIAL
    from cadcnc.pipeline.exit_policy import worst

    assert worst([]) == EXIT_OK
    assert worst([EXIT_OK, EXIT_NOTHING]) == EXIT_NOTHING
    assert worst([EXIT_PARTIAL, EXIT_OK, EXIT_NOTHING]) == EXIT_PARTIAL
    assert worst([EXIT_PARTIAL, EXIT_GOUGE]) == EXIT_GOUGE


def test_setups_give_the_same_bytes_on_two_processes(shared_corner, tmp_path):
    """``--jobs 2`` runs each setup's corners and gate on two worker processes (two corners
    here: the wall's and the fence's), and writes the bytes one process writes."""
    part, floor, wall, step = shared_corner
    fence = next(f.number for f in part.faces if f.kind == "plane" and abs(
        f.point(*(sum(r) / 2 for r in (f.u_range, f.w_range)))[0] - 35) < 1e-9)
    assert part.pair_class(floor, fence) == "concave"
    out = {}
    for jobs in (1, 2):
        d = tmp_path / str(jobs)
        d.mkdir()
        cadcnc_cli("pencil", step, "--radius", R, "--faces", floor, wall, fence, "--setups",
                   "+Z,+X", "--jobs", jobs, "-o", d / "P.json", "-o", d / "P.ngc", check=0)
        out[jobs] = {p.name: p.read_bytes() for p in d.iterdir()}
    assert sorted(out[1]) == ["P+X.json", "P+X.ngc", "P+Z.json", "P+Z.ngc"]
    assert out[1] == out[2]


def test_programs_only_for_the_chosen_setups(shared_corner, monkeypatch):
    """``auto`` judges the six axes from their samples and computes the programs of the
    two it chooses only; each candidate's reach is given, from samples, and where a
    program was computed the samples reach what it reaches."""
    from dataclasses import replace

    import cadcnc
    from cadcnc.core.job import PRINCIPAL_AXES, axis_name
    from cadcnc.ops.pencil import fewest_setups

    part, floor, wall, _ = shared_corner
    job = Job(Tool(R), 1500.0, 0.004, Pencil([floor, wall]), source=part.source)
    planned = []
    real = fewest_setups.operation_of

    def counting(j):
        planned.append(axis_name(j.axis))
        return real(j)

    monkeypatch.setattr(fewest_setups, "operation_of", counting)
    result = fewest_setups.pencil_setups(part, job, "auto")
    assert sorted(planned) == ["+X", "+Z"]
    assert [r.setup.name for r in result.candidates if r.computed] == ["+Z", "+X"]
    assert list(result.reach) == list(fewest_setups.AUTO_ORDER)
    for r in result.candidates:
        assert result.reach[r.setup.name] == r.sampled
        if r.computed:
            assert r.sampled == r.reached > 0
    # +Z y 13..25 and +X y 5..17 in closed form: 12 mm of corner, 25 positions each
    assert abs(result.reach["+Z"] - 12.0 / SPACING - 1) <= 1
    assert abs(result.reach["+X"] - 12.0 / SPACING - 1) <= 1
    for name in ("-Z", "-X", "+Y", "-Y"):   # nothing in the samples
        assert result.reach[name] == 0
    for name in ("-Z", "+Y"):   # nor in a program: the material, an end wall
        assert not cadcnc.run(part, replace(job, axis=PRINCIPAL_AXES[name])).cuts
    assert "from samples; programs computed: +Z +X" in result.summary_lines()[1]


def test_chosen_setups_gates_share_their_work(shared_corner, monkeypatch):
    """Each chosen setup's cut-back step and program gate share one gate cache on its
    turned part (as a single-setup command's do): made once per part and tolerances,
    not once per cut and gate; the verdicts pass."""
    from collections import Counter

    from cadcnc.pipeline.operate import Settings
    from cadcnc.pipeline.setup_programs import run_setups
    from cadcnc.verification import gate_cache

    _, floor, wall, step = shared_corner
    job = Job(Tool(R), 1500.0, 0.004, Pencil([floor, wall]), source=str(step))
    made = []
    real = gate_cache.GateCache.__init__

    def counting(self, part, tol):
        made.append((id(part), tol))
        real(self, part, tol)

    monkeypatch.setattr(gate_cache.GateCache, "__init__", counting)
    run = run_setups(step, job, "auto", 0.0, [], Settings())
    assert [p.setup.name for p in run.programs] == ["+Z", "+X"]
    assert all(p.verdict.gate.ok for p in run.programs)
    parts = {id(r.part) for r in run.result.runs}
    assert len(parts) == 2 and {p for p, _ in made} == parts
    assert set(Counter(made).values()) == {1}
