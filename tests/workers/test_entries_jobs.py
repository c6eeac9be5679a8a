"""Entries looked for on worker processes (issue 24): ``entered_program_segments`` with
``processes=2`` gives the very segments, skips and notes of ``processes=1`` on the entry fixtures
(fixtures/build_entry_fixtures.py): cuts entered at their start, at their end, between
their ends, from the side, and one in a sealed void that no entry reaches."""

from __future__ import annotations

import json

import numpy as np
import pytest

import cadcnc
from cadcnc.core.job import Job, PairPath, Tool
from cadcnc.ops.common import safe_height
from cadcnc.ops.entries import entered_program_segments
from cadcnc.ops.path import pair_program
from helpers.fixtures import FIXTURES

pytestmark = pytest.mark.slow

FACTS = json.loads((FIXTURES / "entry_fixtures.json").read_text())


def _cuts(name: str, monkeypatch):
    """The part, job and the pair's cuts before they are entered."""
    f = FACTS[name]
    part = cadcnc.load_step(str(FIXTURES / f["file"]))
    job = Job(Tool(f["radius"], 0.0), 1500.0, 0.02, PairPath((f["floor"], f["wall"])))
    found: list = []
    monkeypatch.setattr(pair_program, "entered_program",
                        lambda part, job, cuts, skipped, notes=None: found.extend(cuts))
    pair_program.program_for_job(part, job)
    return part, job, found


def _same(a, b) -> bool:
    return a.kind == b.kind and np.array_equal(a.points, b.points) and (
        a.kind != "link" or np.array_equal(a.rapid, b.rapid))


@pytest.mark.parametrize("name", sorted(FACTS))
def test_entries_on_two_processes_are_those_of_one(name, monkeypatch):
    part, job, cuts = _cuts(name, monkeypatch)
    # the sealed corner's cut and the others twice: more cuts than workers
    cuts = cuts + cuts
    z = safe_height(part, job)
    one = entered_program_segments(part, job, cuts, z, join=0.5, processes=1)
    ticks: list = []
    two = entered_program_segments(part, job, cuts, z, join=0.5, processes=2,
                                   tick=lambda k, n: ticks.append((k, n)))
    assert len(one[0]) == len(two[0])
    assert len(one[1]) == (len(cuts) if name == "entry_sealed" else 0)
    assert all(_same(a, b) for a, b in zip(one[0], two[0]))
    assert [(s.faces, s.reason, s.detail) for s in one[1]] == \
        [(s.faces, s.reason, s.detail) for s in two[1]]
    assert one[2] == two[2]
    assert ticks == [(k, len(cuts)) for k in range(1, len(cuts) + 1)]
