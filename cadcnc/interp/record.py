"""The stepper's per-cycle record: named fields in flat, preallocated numeric arrays.

Row K holds the state after cycle K (row 0: the start): the cutter centre, both contacts'
parameters and local geometry, the commanded step f of the cycle that led to it and the
actual step |dp| (both 0 for the start). Arrays grow in chunks (doubling), so a cycle
writes numbers into existing memory and creates no Python objects that outlive it: 45
float64 per cycle, 360 bytes. Index 0/1 of the second axis is surface 1/2.
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


class PathRecord:
    """Per-point log of the cutter centre and both contacts' geometry; see the module doc.

    Each field is a property returning the filled rows as a numpy view, e.g.
    ``record.points`` (N, 3) or ``record.forms`` (N, 2, 6).
    """

    __slots__ = ("_n", "_data")

    def __init__(self, capacity: int = 1024):
        self._n = 0
        self._data = {k: np.empty((capacity, *shape)) for k, shape in FIELDS.items()}

    def __len__(self) -> int:
        return self._n

    @property
    def nbytes_per_row(self) -> int:
        return sum(a[0].nbytes if a.ndim > 1 else a.itemsize for a in self._data.values())

    def _grow(self) -> None:
        for k, a in self._data.items():
            bigger = np.empty((2 * len(a), *a.shape[1:]))
            bigger[:len(a)] = a
            self._data[k] = bigger

    def add(self, p, c1, c2, f: float, step: float, ratio: float = 1.0) -> None:
        """Append one row: centre ``p`` (3-tuple), contacts ``c1``/``c2``, f and |dp| (mm),
        and the accuracy rule's step ratio."""
        n = self._n
        d = self._data
        if n == len(d["steps"]):
            self._grow()
        d["points"][n] = p
        for side, c in ((0, c1), (1, c2)):
            d["uv"][n, side] = c.u, c.w
            d["contacts"][n, side] = c.r
            d["ru"][n, side] = c.ru
            d["rw"][n, side] = c.rw
            d["normals"][n, side] = c.n
            d["forms"][n, side] = c.E, c.F, c.G, c.L, c.M, c.N
        d["commanded"][n] = f
        d["steps"][n] = step
        d["ratio"][n] = ratio
        self._n = n + 1

    def field(self, name: str) -> np.ndarray:
        """The filled rows of field ``name`` (a view; copy it to keep it past new rows)."""
        return self._data[name][:self._n]

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
