"""Shared test helpers: the bundled fixtures and their sidecar facts."""

from __future__ import annotations

import contextlib
import io
import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "fixtures"
SIDECAR = json.loads((FIXTURES / "fixtures.json").read_text())
FIXTURE_NAMES = sorted(SIDECAR)
# every (fixture, i, j) concave pair named in the sidecar
CONCAVE_PAIRS = [(name, *p["faces"]) for name in FIXTURE_NAMES
                 for p in SIDECAR[name]["pairs"] if p["class"] == "concave"]

_parts: dict = {}
os.environ.setdefault("CADCNC_JOBS", "1")  # commands in one process: pytest-xdist has the cores

SLOW_MODULES = {"test_finish.py", "test_fuzz.py", "test_fuzz_operations.py",
                "test_hal_loop.py", "test_controller_stream.py", "test_trim_grid.py",
                "test_gate.py", "test_finish_bounds.py", "test_batch.py", "test_jobs.py",
                "test_waterline_cli.py"}
CLI_MODULES = {"test_cli.py", "test_cli_program.py", "test_cli_smoke.py", "test_cli_units.py",
               "test_pencil_cli.py", "test_finish_cli.py", "test_controller_cli.py",
               "test_outputs.py", "test_bad_input.py", "test_bounds_and_inputs.py",
               "test_fuzz_operations.py", "test_one_job.py", "test_surface_models.py",
               "test_batch.py", "test_waterline_cli.py", "test_programs_identical.py"}


def pytest_xdist_auto_num_workers(config):
    """``-n auto``: a worker per core. (One more worker paid off while a Dask cluster's
    teardown waited ~24 s; now the suite is CPU-bound and a third worker on 2 cores took
    281 s against 260 s, its collection and contention costing more than the waits it
    fills: docs/notes/suite-time.md.)"""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


# The modules that take longest (CPU, or real time waiting on HAL, a cluster, a signal),
# longest first: xdist (``--dist loadscope --no-loadscope-reorder``) hands modules out in
# this order, so that none of them starts last while the other workers sit idle
# (docs/notes/suite-time.md). Modules not listed follow, the most tests first.
LONGEST_FIRST = ["test_jobs.py", "test_hal_loop.py", "test_batch.py", "test_trim_grid.py",
                 "test_finish.py", "test_gate.py", "test_cli.py", "test_verification.py",
                 "test_outputs.py", "test_fuzz.py", "test_waterline_cli.py", "test_axis.py",
                 "test_axis_finish.py", "test_fuzz_operations.py", "test_finish_reverse.py"]


def pytest_collection_modifyitems(config, items):
    """The markers of pyproject.toml, by module: ``slow`` and ``cli``; the modules in
    LONGEST_FIRST order (a module's tests stay together, in their order)."""
    for item in items:
        name = item.path.name
        if name in SLOW_MODULES:
            item.add_marker(pytest.mark.slow)
        if name in CLI_MODULES:
            item.add_marker(pytest.mark.cli)
    count: dict = {}
    for item in items:
        count[item.path] = count.get(item.path, 0) + 1
    rank = {name: k for k, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: (rank.get(item.path.name, len(rank)), -count[item.path],
                                 str(item.path)))


def load_fixture(name: str):
    """The fixture's Part, loaded once per test session."""
    import cadcnc

    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIXTURES / SIDECAR[name]["file"])
    return _parts[name]


def occt_distance(point, shape) -> float:
    """OCCT's distance (mm) from a point (3,) to a shape: BRepExtrema_DistShapeShape."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.gp import gp_Pnt

    d = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, point)))
                                   .Vertex(), shape)
    d.Perform()
    assert d.IsDone()
    return d.Value()


def random_cell_boxes(face, boxes, rng, n: int):
    """n random parameter cells of ``face``: (box (6,) from ``boxes.box``, points (49, 3)
    of the face sampled on the cell), for the box-holds-its-surface tests."""
    (u0, u1), (w0, w1) = face.u_range, face.w_range
    out = []
    for _ in range(n):
        a, b = sorted(rng.uniform(u0, u1, 2))
        c, d = sorted(rng.uniform(w0, w1, 2))
        pts = [face.point(u, w) for u in np.linspace(a, b, 7) for w in np.linspace(c, d, 7)]
        out.append((np.array(boxes.box(a, b, c, d)), np.array(pts), (b - a, d - c)))
    return out


@pytest.fixture
def fixture_part():
    return load_fixture


_paths: dict = {}


def fixture_path(name: str, i: int, j: int, *, radius: float = 3.0, feed: float = 1500.0,
                 period: float = 0.004, **kwargs):
    """The toolpath of a fixture pair, computed once per test session (do not modify it)."""
    key = (name, i, j, radius, feed, period, tuple(sorted(kwargs.items())))
    if key not in _paths:
        import cadcnc

        part = load_fixture(name)
        _paths[key] = cadcnc.intersection_path(part.face(i), part.face(j), radius=radius,
                                               feed=feed, period=period, **kwargs)
    return _paths[key]


@dataclass
class Run:
    """What one in-process ``cadcnc`` run left: its exit code, stdout and stderr."""
    returncode: int
    stdout: str
    stderr: str


@contextlib.contextmanager
def _cwd(path):
    old = os.getcwd()
    os.chdir(path or old)
    try:
        yield
    finally:
        os.chdir(old)


def cadcnc_cli(*args, cwd=None, check=None) -> Run:
    """Run ``cadcnc ARGS`` in this process (``cadcnc.cli.app.main``); returns its exit code,
    stdout and stderr. ``check``: the exit code it must give."""
    from cadcnc.cli.app import main

    out, err = io.StringIO(), io.StringIO()
    with _cwd(cwd), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main([str(a) for a in args])
        except SystemExit as e:  # argparse: --help, usage errors
            code = e.code
    run = Run(code, out.getvalue(), err.getvalue())
    if check is not None:
        assert run.returncode == check, (run.returncode, run.stdout, run.stderr)
    return run


BOSS_JOB = ["--faces", "4", "5", "--radius", "3", "--feed", "1500", "--period", "4ms"]


@pytest.fixture(scope="session")
def boss_cli_outputs(tmp_path_factory):
    """(folder, run): ``cadcnc path bspline_boss.step BOSS_JOB -o p.json -o p.csv -o p.ngc``
    run once per test session (in-process), shared by the modules that read its program or
    its summary (do not modify the files)."""
    d = tmp_path_factory.mktemp("boss_path")
    run = cadcnc_cli("path", FIXTURES / "bspline_boss.step", *BOSS_JOB, "-o", d / "p.json",
                     "-o", d / "p.csv", "-o", d / "p.ngc", check=0)
    return d, run
