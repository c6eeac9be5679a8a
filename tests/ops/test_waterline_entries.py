"""Waterline loops are entered by the one entry rule (cadcnc.ops.entries), as raster
passes and pencil corners are: a level under an overhang is reached from the side.

Fixture ``entry_side`` (fixtures/build_entry_fixtures.py): a wall x = 40 with an overhang
over all of it at z 36..40. With R 2 and its 20 mm shank, the levels at z 12 and 14
fit under the overhang, and no plunge from above reaches them. Before, waterline linked
its loops by plunging from the clearance height: the gate refused the program (exit 5,
a blocked link). Judged by the gate (OCCT's distances), not by the entry rule's guard.
"""

from __future__ import annotations

import json

import cadcnc
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "entry_fixtures.json").read_text())["entry_side"]


def test_levels_under_an_overhang_are_entered_from_the_side():
    part = cadcnc.load_step(FIXTURES / FACTS["file"])
    prog = cadcnc.finish(part, [FACTS["wall"]], radius=FACTS["radius"],
                         strategy="waterline", stepdown=2.0)
    assert prog.cuts, prog.skipped
    assert any("from the -X side" in note for note in prog.notes), prog.notes
    gate = cadcnc.gate_program(prog, part)
    assert gate.ok, gate.message
    assert not any(gate.link_failed)
    # every level cut lies under the overhang with its shank: z <= 36 - 20 (shank) - 2
    assert max(float(seg.points[:, 2].max()) for seg in prog.cuts) <= 14.0 + 1e-9
    # the tool comes in from outside the part's box (x < 0) at the first level's height
    first = prog.segments[0]
    assert first.kind == "link"
    assert first.points[-2, 0] < 0.0 and first.points[-2, 2] == first.points[-1, 2]
