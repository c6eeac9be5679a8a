"""Shared test helpers: the bundled fixtures and their sidecar facts."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "fixtures"
SIDECAR = json.loads((FIXTURES / "fixtures.json").read_text())
FIXTURE_NAMES = sorted(SIDECAR)
# every (fixture, i, j) concave pair named in the sidecar
CONCAVE_PAIRS = [(name, *p["faces"]) for name in FIXTURE_NAMES
                 for p in SIDECAR[name]["pairs"] if p["class"] == "concave"]

_parts: dict = {}


def load_benchmark(name: str):
    """A benchmarks/ module by file path, registered under its name; benchmarks/ goes at
    the end of sys.path so that its sibling imports resolve (installed packages first)."""
    if str(ROOT / "benchmarks") not in sys.path:
        sys.path.append(str(ROOT / "benchmarks"))
    spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def load_fixture(name: str):
    """The fixture's Part, loaded once per test session."""
    import cadcnc

    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIXTURES / SIDECAR[name]["file"])
    return _parts[name]


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
