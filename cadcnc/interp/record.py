"""The stepper's per-cycle record: named fields in flat, preallocated numeric arrays.

Row K holds the state after cycle K (row 0: the start): the cutter centre, both contacts'
parameters and local geometry, the commanded step f of the cycle that led to it and the
actual step |dp| (both 0 for the start). Arrays grow in chunks (doubling), so a cycle
writes numbers into existing memory and creates no Python objects that outlive it: 46
float64 per cycle, 368 bytes (one row of one array). Index 0/1 of the second axis is
surface 1/2.
"""

from __future__ import annotations

import numpy as np

# name -> per-row shape; the order is the order of the columns in memory
FIELDS = {
    "points": (3,),      # cutter centre p, mm
    "uv": (2, 2),        # contact parameters (u, w) per surface
    "contacts": (2, 3),  # contact points r(u, w), mm
    "ru": (2, 3),        # r_u at the contacts, mm per unit u
    "rw": (2, 3),        # r_w at the contacts
    "normals": (2, 3),   # unit normals out of the material
    "forms": (2, 6),     # E, F, G (first form) and L, M, N (second form, against n)
    "commanded": (),     # commanded step f of the cycle into this row, mm
    "steps": (),         # actual step |dp| into this row, mm
    "ratio": (),         # step / commanded step where the accuracy rule shortened it, else 1
}


COLUMNS = {}
"""name -> (first column, per-row shape) in the record's (capacity, ROW) array."""
_col = 0
for _name, _shape in FIELDS.items():
    COLUMNS[_name] = (_col, _shape)
    _col += int(np.prod(_shape, dtype=int))
ROW = _col   # 46 float64: 368 bytes per cycle


class PathRecord:
    """Per-point log of the cutter centre and both contacts' geometry; see the module doc.

    Each field is a property returning the filled rows as a numpy view, e.g.
    ``record.points`` (N, 3) or ``record.forms`` (N, 2, 6). All fields live in one
    (capacity, ROW) float64 array, ``rows``, which the compiled stepper writes directly.
    """

    __slots__ = ("_n", "rows")

    def __init__(self, capacity: int = 1024):
        self._n = 0
        self.rows = np.empty((capacity, ROW))

    def __len__(self) -> int:
        return self._n

    @property
    def nbytes_per_row(self) -> int:
        return self.rows[0].nbytes

    def grow(self) -> None:
        """Double the capacity (the filled rows are kept)."""
        bigger = np.empty((2 * len(self.rows), ROW))
        bigger[:len(self.rows)] = self.rows
        self.rows = bigger

    def set_length(self, n: int) -> None:
        """Rows 0..n-1 are filled (after the compiled stepper wrote them)."""
        self._n = n

    def add(self, p, c1, c2, f: float, step: float, ratio: float = 1.0) -> None:
        """Append one row: centre ``p`` (3-tuple), contacts ``c1``/``c2``, f and |dp| (mm),
        and the accuracy rule's step ratio."""
        n = self._n
        if n == len(self.rows):
            self.grow()
        row = self.rows[n]
        row[0:3] = p
        row[3:7] = c1.u, c1.w, c2.u, c2.w
        col = 7
        for name in ("r", "ru", "rw", "n"):
            row[col:col + 3] = getattr(c1, name)
            row[col + 3:col + 6] = getattr(c2, name)
            col += 6
        row[31:37] = c1.E, c1.F, c1.G, c1.L, c1.M, c1.N
        row[37:43] = c2.E, c2.F, c2.G, c2.L, c2.M, c2.N
        row[43:46] = f, step, ratio
        self._n = n + 1

    def field(self, name: str) -> np.ndarray:
        """The filled rows of field ``name`` (a view; copy it to keep it past new rows)."""
        col, shape = COLUMNS[name]
        width = int(np.prod(shape, dtype=int))
        if not shape:
            return self.rows[:self._n, col]
        return self.rows[:self._n, col:col + width].reshape((self._n, *shape))
    points = property(lambda self: self.field("points"))
    uv = property(lambda self: self.field("uv"))
    contacts = property(lambda self: self.field("contacts"))
    ru = property(lambda self: self.field("ru"))
    rw = property(lambda self: self.field("rw"))
    normals = property(lambda self: self.field("normals"))
    forms = property(lambda self: self.field("forms"))
    commanded = property(lambda self: self.field("commanded"))
    steps = property(lambda self: self.field("steps"))
    ratio = property(lambda self: self.field("ratio"))
