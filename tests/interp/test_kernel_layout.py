"""The compiled stepper's array layout (cadcnc/interp/kernel/layout.py): every field of the
state has its own slots inside the state, the headers' slots fit their headers, and the
record's columns are record.FIELDS'."""

from __future__ import annotations

from cadcnc.interp.kernel import layout as L
from cadcnc.interp.record import COLUMNS, ROW


def _slots(fields: dict[str, tuple[int, int]]) -> dict[int, str]:
    taken: dict[int, str] = {}
    for name, (offset, width) in fields.items():
        for k in range(offset, offset + width):
            assert k not in taken, f"{name} and {taken[k]} share slot {k}"
            taken[k] = name
    return taken


def test_state_fields_are_distinct_and_inside_the_state():
    taken = _slots(L.STATE)
    assert min(taken) >= 0 and max(taken) < L.STATE_SIZE
    named = {k: v for k, v in vars(L).items() if k.isupper() and k in L.STATE}
    assert named == {k: off for k, (off, _) in L.STATE.items()}


def test_contact_blocks_hold_a_contact():
    contact = {k: v for k, v in vars(L).items() if k.startswith("C_")}
    fields = {k: (v, 3 if k in ("C_R", "C_RU", "C_RW", "C_NRM") else 1) for k, v in contact.items()}
    assert max(_slots(fields)) < L.CS
    assert L.N1 - L.C1 == L.KEPT1 - L.N1 == 2 * L.CS


def test_header_slots_are_distinct_and_inside_a_header():
    for prefix, used in (("H_", L.HEAD), ("G_", L.G_USED)):
        slots = {k: v for k, v in vars(L).items() if k.startswith(prefix) and k != "G_USED"}
        assert len(set(slots.values())) == len(slots), prefix
        assert sorted(slots.values()) == list(range(used)), prefix
    assert L.G_USED <= L.HEAD and L.HEADERS == 2 * L.HEAD


def test_record_columns_are_the_records():
    assert L.ROW == ROW
    assert (L.R_POINTS, L.R_UV, L.R_CONTACTS, L.R_FORMS) == tuple(
        COLUMNS[k][0] for k in ("points", "uv", "contacts", "forms"))
    assert (L.R_COMMANDED, L.R_STEP, L.R_RATIO) == tuple(
        COLUMNS[k][0] for k in ("commanded", "steps", "ratio"))
