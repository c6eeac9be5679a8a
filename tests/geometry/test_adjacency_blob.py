"""A worker's part takes the caller's edge classification instead of classifying again.

``part_blob`` carries a computed adjacency as plain numbers; ``part_from_blob`` gives it
to the rebuilt part with the rebuilt shape's own edges. Judged against what the rebuilt
part computes itself (its own classification of its own edges, the same fields bit for
bit) and against OCCT's evaluation of the edges it was given (their curves start and end
where the record says). A part turned into a setup carries the turned part's adjacency;
a part without a computed adjacency, or a record that does not fit, classifies as usual.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from OCP.BRep import BRep_Builder
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.gp import gp_Pnt
from OCP.TopoDS import TopoDS_Compound

import cadcnc
from cadcnc.geometry.part import Part
from cadcnc.geometry.part_bytes import (
    adjacency_record,
    part_blob,
    part_from_blob,
    take_adjacency_record,
)
from cadcnc.geometry.setup import setup_in, setup_of, setup_part
from helpers.fixtures import FIXTURES

EXACT = ("faces", "edge_class", "length", "closed")
ARRAYS = ("angles_deg", "points", "start", "end", "start_tangent", "end_tangent")


@pytest.fixture
def classified(monkeypatch) -> list:
    """Counts the edges classified from now on."""
    seen: list = []
    classify = Part._classify_edge

    def counting(self, edge, *args, **kwargs):
        seen.append(edge)
        return classify(self, edge, *args, **kwargs)

    monkeypatch.setattr(Part, "_classify_edge", counting)
    return seen


def fresh(name: str) -> Part:
    return cadcnc.load_step(FIXTURES / name)   # not the suite's shared parts: no adjacency yet


def through_pickle(blob: tuple) -> tuple:
    return pickle.loads(pickle.dumps(blob))   # as a worker receives it


def assert_same_adjacency(a: Part, b: Part) -> None:
    """Every SharedEdge field of ``b`` equal to ``a``'s, in the same order, bit for bit."""
    assert list(a.adjacency) == list(b.adjacency)
    for pair, edges in a.adjacency.items():
        assert len(edges) == len(b.adjacency[pair])
        for x, y in zip(edges, b.adjacency[pair]):
            for f in EXACT:
                assert getattr(x, f) == getattr(y, f), (pair, f)
            for f in ARRAYS:
                assert np.array_equal(getattr(x, f), getattr(y, f)), (pair, f)


def assert_own_edges(part: Part) -> None:
    """The adjacency's edges are ``part``'s, and their curves start and end at the
    recorded points (OCCT's evaluation of the edge given)."""
    emap = part.edge_map()
    for edges in part.adjacency.values():
        for e in edges:
            k = emap.FindIndex(e.edge)
            assert k > 0 and emap.FindKey(k).IsSame(e.edge)
            curve, p = BRepAdaptor_Curve(e.edge), gp_Pnt()
            curve.D0(curve.FirstParameter(), p)
            assert np.array_equal(p.Coord(), e.start)
            curve.D0(curve.LastParameter(), p)
            assert np.array_equal(p.Coord(), e.end)


@pytest.mark.parametrize("name", ["step_slot.step", "pocket.step"])
def test_the_rebuilt_part_takes_the_adjacency_without_classifying(name, classified):
    part = fresh(name)
    part.adjacency
    n = len(classified)
    assert n == sum(len(v) for v in part.adjacency.values()) > 10
    rebuilt = part_from_blob(*through_pickle(part_blob(part)))
    assert rebuilt.adjacency_known
    assert_same_adjacency(part, rebuilt)
    assert len(classified) == n   # nothing classified again
    assert_own_edges(rebuilt)
    assert not any(x.edge.IsSame(y.edge) for x, y in zip(
        *(sum(p.adjacency.values(), []) for p in (part, rebuilt))))  # not the caller's
    # what the rebuilt shape's own classification gives: the same, bit for bit
    own = part_from_blob(*part_blob(part)[:6])
    assert not own.adjacency_known
    assert_same_adjacency(own, rebuilt)
    assert len(classified) == 2 * n


def test_a_part_without_adjacency_classifies_in_the_worker(classified):
    part = fresh("pocket.step")
    blob = part_blob(part)
    assert blob[6] is None and not part.adjacency_known
    rebuilt = part_from_blob(*through_pickle(blob))
    assert not rebuilt.adjacency_known and not classified
    assert_same_adjacency(part, rebuilt)   # both classify here
    assert len(classified) == 2 * sum(len(v) for v in part.adjacency.values())


def test_a_setup_part_carries_the_turned_adjacency(classified):
    part = fresh("step_slot.step")
    turned = setup_part(part, setup_of(part, (0.0, 1.0, 1.0)))
    part.adjacency   # the original's: not the one to carry
    assert part_blob(turned)[6] is None
    turned.adjacency
    n = len(classified)
    rebuilt = part_from_blob(*through_pickle(part_blob(turned)))
    assert setup_in(rebuilt) is not None and rebuilt.adjacency_known
    assert_same_adjacency(turned, rebuilt)
    assert len(classified) == n
    assert_own_edges(rebuilt)
    # turned coordinates: not the original's points
    first = next(iter(part.adjacency))
    assert not np.allclose(part.adjacency[first][0].points,
                           rebuilt.adjacency[first][0].points, atol=1e-3)
    own = part_from_blob(*part_blob(turned)[:6])
    assert setup_in(own) is not None and not own.adjacency_known
    assert_same_adjacency(own, rebuilt)


def test_a_record_that_does_not_fit_is_dropped(classified):
    slot, pocket = fresh("step_slot.step"), fresh("pocket.step")
    slot.adjacency, pocket.adjacency
    extent, rows = adjacency_record(slot)
    other = part_from_blob(*part_blob(pocket)[:6])
    assert not take_adjacency_record(other, (extent, rows))   # another part
    assert not other.adjacency_known
    same = part_from_blob(*part_blob(slot)[:6])
    assert not take_adjacency_record(same, (extent, rows[1:]))   # an edge missing
    a, b = rows[0], rows[-1]
    assert a[1] != b[1]
    swapped = [(b[0],) + a[1:]] + rows[1:-1] + [(a[0],) + b[1:]]   # edges swapped
    assert not take_adjacency_record(same, (extent, swapped))
    assert not take_adjacency_record(same, (extent + 1, rows))
    assert not same.adjacency_known
    assert take_adjacency_record(same, (extent, rows))
    assert_same_adjacency(slot, same)


def test_a_free_edge_beside_the_faces_is_no_shared_edge():
    """An edge no face holds (a wire in the compound) is left out, as a seam is."""
    builder, both = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(both)
    builder.Add(both, fresh("step_slot.step").shape)
    builder.Add(both, BRepBuilderAPI_MakeEdge(gp_Pnt(500, 0, 0), gp_Pnt(510, 0, 0)).Edge())
    part, alone = Part(both), fresh("step_slot.step")
    assert_same_adjacency(alone, part)
