"""The repository's fixtures (``fixtures/``): their sidecar facts, parts and pair paths, each
computed once per test session (do not modify them)."""

from __future__ import annotations

import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "fixtures"
SIDECAR = json.loads((FIXTURES / "fixtures.json").read_text())
FIXTURE_NAMES = sorted(SIDECAR)
# every (fixture, i, j) concave pair named in the sidecar
CONCAVE_PAIRS = [(name, *p["faces"]) for name in FIXTURE_NAMES
                 for p in SIDECAR[name]["pairs"] if p["class"] == "concave"]

_parts: dict = {}
_paths: dict = {}


def load_fixture(name: str):
    """The fixture's Part, loaded once per test session."""
    import cadcnc

    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIXTURES / SIDECAR[name]["file"])
    return _parts[name]


def fixture_path(name: str, i: int, j: int, *, radius: float = 3.0, feed: float = 1500.0,
                 period: float = 0.004, **kwargs):
    """The toolpath of a fixture pair, computed once per test session (do not modify it)."""
    key = (name, i, j, radius, feed, period, tuple(sorted(kwargs.items())))
    if key not in _paths:
        from cadcnc.ops.path.pair_path import intersection_path

        part = load_fixture(name)
        _paths[key] = intersection_path(part.face(i), part.face(j), radius=radius,
                                        feed=feed, period=period, **kwargs)
    return _paths[key]


STRETCH_SIDECAR = json.loads((FIXTURES / "stretch_fixtures.json").read_text())


def stretch_pair_job(name: str):
    """(s1, s2, job) of a stretch fixture's pair: its ball radius and shank length, feed
    1500 mm/min, period 4 ms (a fresh part each call: guards built on it start empty)."""
    from dataclasses import replace

    import cadcnc
    from cadcnc.core.job import Tool
    from cadcnc.ops.path.pair_path import pair_job

    facts = STRETCH_SIDECAR[name]
    part = cadcnc.load_step(FIXTURES / facts["file"])
    i, j = facts["pair"]
    s1, s2, job = pair_job(part.face(i), part.face(j), radius=facts["radius"],
                           feed=1500.0, period=0.004)
    return s1, s2, replace(job, tool=Tool(facts["radius"], 0.0, facts["shank"]))
