"""A hit proven from a nearby measured one (ClearanceGuard.proven_hit) is a true upper
bound of the clearance, never taken where a shared edge may be nearest; the first face
found cutting in (first_hit) is one of the faces that cut in; and the stretch search
that takes such hits finds the same stretches and refusals as with exact clearances."""

from __future__ import annotations

import json

import numpy as np
import pytest

import cadcnc
from cadcnc.guard.clearance import ClearanceGuard
from cadcnc.ops.path.stretches import pair_stretches
from helpers.fixtures import FIXTURES, stretch_pair_job

SIDECAR = json.loads((FIXTURES / "stretch_fixtures.json").read_text())
TOL = 1e-6   # mm: the guard's hit tolerance in these tests


def _shelf_guard() -> ClearanceGuard:
    facts = SIDECAR["shelf"]
    part = cadcnc.load_step(FIXTURES / facts["file"])
    return ClearanceGuard(part, facts["pair"], facts["radius"], facts["shank"], TOL)


def test_a_proven_hit_bounds_the_exact_clearance_from_above():
    """Under the shelf (x 25..35 on the corner line) the shank cuts 2 mm past the shelf's
    side (face 12, which meets the wall) and 1 mm past face 16 (which touches neither
    floor nor wall): measured at x = 30, they prove the hits up to 3 mm away without a
    measurement, each bound above the exact clearance."""
    g = _shelf_guard()
    assert g.proven_hit((30.0, 8.0, 11.0)) is None        # nothing measured yet
    m0, _ = g.margin((30.0, 8.0, 11.0))
    assert m0 < 0.0
    for dx in (0.0, 0.5, 1.5, 2.99):
        p = (30.0 + dx, 8.0, 11.0)
        bound, detail = g.proven_hit(p)
        exact, _ = _shelf_guard().margin(p)
        assert exact <= bound < 0.0
        assert detail == "shank touches face 12"   # the deepest: 2 mm past the side
    assert g.proven_hit((33.5, 8.0, 11.0)) is None        # past |m0| of centre: unproven


def test_every_proof_bounds_the_exact_clearance_along_the_corner():
    """Along the shelf fixture's corner line (x 0..40) the tool meets faces that touch
    the pair (the end walls 3 and 7, the shelf's side 12) and faces that do not (1, 16):
    measured every 0.5 mm, each proof 0.25 mm further on is an upper bound of the exact
    clearance there."""
    g = _shelf_guard()
    xs = np.arange(0.0, 40.0, 0.5)
    proven = 0
    for x in xs:
        g.margin((float(x), 8.0, 11.0))
        p = (float(x) + 0.25, 8.0, 11.0)
        exact, _ = _shelf_guard().margin(p)
        hit = g.proven_hit(p)
        if hit is not None:
            proven += 1
            assert exact <= hit[0] < 0.0, (x, exact, hit)
    assert proven >= 46   # of the 48 positions that are hits (47 proven today)


def test_a_face_sharing_an_edge_proves_nothing_where_that_edge_may_be_nearest():
    """Under the shelf the shank meets face 12 (it shares an edge with the wall) and
    face 16 (apart). With the shared edges' bound at 0 (as on that edge itself) only
    face 16 still proves the hit."""
    g = _shelf_guard()
    g.margin((30.0, 8.0, 11.0))
    assert g._shared_distance(16, (30.0, 8.0, 11.0)) == float("inf")
    assert 0.0 <= g._shared_distance(12, (30.0, 8.0, 11.0)) < float("inf")
    measured = set(g._hits)
    assert {12, 16} <= measured
    g._shared_distance = lambda k, p: float("inf") if k == 16 else 0.0
    assert g.proven_hit((30.5, 8.0, 11.0))[1] == "shank touches face 16"


def test_the_first_hit_is_a_face_that_cuts_in():
    """Under the shelf (x = 30) faces 12 and 16 cut in: the first one found is one of
    them, its margin an upper bound of the clearance; where nothing cuts in (x = 15) the
    answer is the exact clearance."""
    exact, detail = _shelf_guard().margin((30.0, 8.0, 11.0))
    m, first, whole = _shelf_guard().first_hit((30.0, 8.0, 11.0))
    assert not whole and exact <= m < 0.0
    assert first in ("shank touches face 12", "shank touches face 16")
    assert _shelf_guard().first_hit((15.0, 8.0, 11.0)) == (
        *_shelf_guard().margin((15.0, 8.0, 11.0)), True)


@pytest.mark.parametrize("name", ["shelf", "slot"] + [
    pytest.param(n, marks=pytest.mark.slow) for n in ("pocket", "sloped", "undercut", "boss")])
def test_quick_samples_find_the_same_stretches(name, monkeypatch):
    s1, s2, job = stretch_pair_job(name)
    proofs = []   # (a proof per call: True when it took a hit without OCCT)
    prove = ClearanceGuard.proven_hit

    def counted(self, p):
        got = prove(self, p)
        proofs.append(got is not None)
        return got

    monkeypatch.setattr(ClearanceGuard, "proven_hit", counted)
    quick = pair_stretches(s1, s2, job)
    if name in ("shelf", "slot"):
        assert any(proofs)    # the comparison below is not vacuous
    monkeypatch.setattr(ClearanceGuard, "proven_hit", lambda self, p: None)
    monkeypatch.setattr(ClearanceGuard, "first_hit", lambda self, p: (*self.margin(p), True))
    exact = pair_stretches(s1, s2, job)
    assert [e.refusal for e in quick] == [e.refusal for e in exact]
    assert [[(st.start, st.end) for st in e.stretches] for e in quick] == \
        [[(st.start, st.end) for st in e.stretches] for e in exact]
