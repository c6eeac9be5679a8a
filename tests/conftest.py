"""The suite's hooks: markers derived from where a test sits and what it runs, modules handed
to the workers longest first (by the durations the last runs recorded), and the fixtures the
modules share. Shared helpers are the ``helpers`` package; independent references are
:mod:`cadcnc.testing`."""

from __future__ import annotations

import os

import pytest

from helpers import cli, fixtures

os.environ.setdefault("CADCNC_JOBS", "1")  # commands in one process: pytest-xdist has the cores

DURATIONS = "cadcnc/module-seconds"
"""The pytest cache key (``.pytest_cache``) of each test module's recorded time, s."""
GUESS_SLOW, GUESS_FAST = 5.0, 0.5
"""s per test of a module no run has recorded yet: ``slow`` (over about 5 s each) or not."""


def pytest_xdist_auto_num_workers(config):
    """``-n auto``: a worker per core. (One more worker paid off while a Dask cluster's
    teardown waited ~24 s; now the suite is CPU-bound and a third worker on 2 cores took
    281 s against 260 s, its collection and contention costing more than the waits it
    fills: docs/notes/suite-time.md.)"""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _module(nodeid: str) -> str:
    return nodeid.split("::")[0]


def _runs_the_cli(item) -> bool:
    """The module sits in ``tests/cli/`` or runs the command in process (``cadcnc_cli``)."""
    return (item.path.parent.name == "cli"
            or getattr(item.module, "cadcnc_cli", None) is cli.cadcnc_cli)


def _recorded(config) -> dict:
    """The modules' recorded times: read from the cache by the controller, handed to each
    xdist worker with its input (so that every worker collects in one order)."""
    worker = getattr(config, "workerinput", None)
    if worker is not None and DURATIONS in worker:
        return worker[DURATIONS]
    cache = getattr(config, "cache", None)
    return cache.get(DURATIONS, {}) if cache is not None else {}


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """xdist, on the controller: a worker's input carries the recorded times."""
    node.workerinput[DURATIONS] = _recorded(node.config)


def pytest_collection_modifyitems(config, items):
    """The ``cli`` marker where a module runs the command line; the modules longest first
    (a module's tests stay together, in their order), so that xdist (``--dist loadscope
    --no-loadscope-reorder``) starts none of the long ones last while the other workers
    sit idle (docs/notes/suite-time.md). A module's length is its recorded time, or its
    test count times a guess by its ``slow`` marker."""
    for item in items:
        if _runs_the_cli(item):
            item.add_marker(pytest.mark.cli)
    recorded = _recorded(config)
    count: dict = {}
    slow: dict = {}
    for item in items:
        name = _module(item.nodeid)
        count[name] = count.get(name, 0) + 1
        slow[name] = slow.get(name, False) or item.get_closest_marker("slow") is not None
    length = {name: recorded.get(name, n * (GUESS_SLOW if slow[name] else GUESS_FAST))
              for name, n in count.items()}
    items.sort(key=lambda item: (-length[_module(item.nodeid)], _module(item.nodeid)))


_seconds: dict = {}


def pytest_runtest_logreport(report):
    """Each module's time, summed over its tests' setup, call and teardown (on the
    controller, from every worker's reports)."""
    name = _module(report.nodeid)
    _seconds[name] = _seconds.get(name, 0.0) + report.duration


def pytest_sessionfinish(session, exitstatus):
    """The modules' times into the cache, for the next run's order: only from the
    controller (or a run without workers), only for whole modules (no ``-k``, no test
    ids), and not from an interrupted run."""
    config = session.config
    cache = getattr(config, "cache", None)
    partial = config.option.keyword or any("::" in a for a in config.args)
    if (cache is None or hasattr(config, "workerinput") or partial or not _seconds
            or exitstatus == pytest.ExitCode.INTERRUPTED):
        return
    recorded = cache.get(DURATIONS, {})
    recorded.update({name: round(s, 2) for name, s in _seconds.items()})
    cache.set(DURATIONS, recorded)


@pytest.fixture(scope="session")
def boss_cli_outputs(tmp_path_factory):
    """(folder, run): ``cadcnc path bspline_boss.step BOSS_JOB -o p.json -o p.csv -o p.ngc``
    run once per test session (in-process), shared by the modules that read its program or
    its summary (do not modify the files)."""
    d = tmp_path_factory.mktemp("boss_path")
    run = cli.cadcnc_cli("path", fixtures.FIXTURES / "bspline_boss.step", *cli.BOSS_JOB,
                         "-o", d / "p.json", "-o", d / "p.csv", "-o", d / "p.ngc", check=0)
    return d, run
