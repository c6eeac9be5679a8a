"""A B-spline's numbers read from OCCT in one call (BinTools) instead of one per pole.

Reading a B-spline through OCP costs about 0.6 us a pole and 0.25 us a knot (a Python call
each): 0.15-0.3 ms for the pcurves and surfaces of one face, a large share of a trim grid's
build. OCCT's binary BRep writer (``BinTools``) writes a shape's geometry in one call
(about 10 us): the curve or surface is put alone in a bare edge or face, written, and its
record (BinTools' format: little-endian doubles and int32s) read with numpy.

Every read is checked against OCCT: the record's header (degree, counts, rational and
periodic flags) and the first, middle and last poles and the end knots must equal the
handle's own values exactly, and the multiplicities must sum to what the pole count implies.
Anything else returns None, and the caller reads the B-spline pole by pole.
"""

from __future__ import annotations

import io

import numpy as np
from OCP.BinTools import BinTools, BinTools_FormatVersion_VERSION_4
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge2d
from OCP.TopoDS import TopoDS_Face

from ..core.tolerances import CONFUSION

_CURVE_2D, _SURFACE = 7, 9   # BinTools' record tags of Geom2d_BSplineCurve, Geom_BSplineSurface
_KNOT = np.dtype([("t", "<f8"), ("m", "<i4")])


def _blob(shape) -> bytes:
    stream = io.BytesIO()
    BinTools.Write_s(shape, stream, False, False, BinTools_FormatVersion_VERSION_4)
    return stream.getvalue()


def _record(blob: bytes, section: bytes, header: bytes) -> int | None:
    """Offset just after ``header`` in the one-record ``section`` of ``blob``, or None."""
    start = blob.find(b"\n" + section + b" 1\n")
    if start < 0:
        return None
    at = start + len(section) + 4
    return at + len(header) if blob.startswith(header, at) else None


def _knots(blob: bytes, at: int, count: int) -> tuple[np.ndarray, np.ndarray, int]:
    rec = np.frombuffer(blob, _KNOT, count, at)
    return rec["t"].astype(float), rec["m"].astype(np.int64), at + count * _KNOT.itemsize


def _counts_agree(mults: np.ndarray, poles: int, degree: int, periodic: bool) -> bool:
    """Whether the multiplicities sum as OCCT relates them to the poles: n + degree + 1
    for a non-periodic B-spline, n for a periodic one (its last knot repeats the first)."""
    return int(mults[:-1].sum()) == poles if periodic else int(mults.sum()) == poles + degree + 1


def curve2d(bs) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """(poles (n, 2), weights (n,) or empty, knots (k,), multiplicities (k,)) of a
    Geom2d_BSplineCurve, or None (not readable this way: read it pole by pole)."""
    n, k, rational = bs.NbPoles(), bs.NbKnots(), bs.IsRational()
    header = (bytes([_CURVE_2D, rational, bs.IsPeriodic()]) + bs.Degree().to_bytes(2, "little")
              + n.to_bytes(4, "little") + k.to_bytes(4, "little"))
    blob = _blob(BRepBuilderAPI_MakeEdge2d(bs).Edge())
    at = _record(blob, b"Curve2ds", header)
    if at is None:
        return None
    width = 3 if rational else 2
    rows = np.frombuffer(blob, "<f8", n * width, at).reshape(n, width).astype(float)
    knots, mults, _ = _knots(blob, at + rows.nbytes, k)
    poles, weights = rows[:, :2], (rows[:, 2].copy() if rational else np.zeros(0))
    ok = all(tuple(poles[i - 1]) == bs.Pole(i).Coord() for i in {1, (n + 1) // 2, n})
    ok = ok and knots[0] == bs.Knot(1) and knots[-1] == bs.Knot(k)
    ok = ok and _counts_agree(mults, n, bs.Degree(), bs.IsPeriodic())
    ok = ok and (not rational or weights[n // 2] == bs.Weight(n // 2 + 1))
    return (poles.copy(), weights, knots, mults) if ok else None


def surface(bs) -> tuple[np.ndarray, np.ndarray, tuple, tuple] | None:
    """(poles (nu, nv, 3), weights (nu, nv) or None, (u knots, u multiplicities), (v knots,
    v multiplicities)) of a Geom_BSplineSurface, or None."""
    nu, nv, ku, kv = bs.NbUPoles(), bs.NbVPoles(), bs.NbUKnots(), bs.NbVKnots()
    rational = bs.IsURational() or bs.IsVRational()
    header = (bytes([_SURFACE, bs.IsURational(), bs.IsVRational(), bs.IsUPeriodic(),
                     bs.IsVPeriodic()]) + bs.UDegree().to_bytes(2, "little")
              + bs.VDegree().to_bytes(2, "little")
              + b"".join(x.to_bytes(4, "little") for x in (nu, nv, ku, kv)))
    face = TopoDS_Face()
    BRep_Builder().MakeFace(face, bs, CONFUSION)
    blob = _blob(face)
    at = _record(blob, b"Surfaces", header)
    if at is None:
        return None
    width = 4 if rational else 3
    rows = np.frombuffer(blob, "<f8", nu * nv * width, at).reshape(nu, nv, width).astype(float)
    *u, at = _knots(blob, at + rows.nbytes, ku)
    v = _knots(blob, at, kv)[:2]
    poles = rows[:, :, :3].copy()
    corners = {(1, 1), ((nu + 1) // 2, (nv + 1) // 2), (nu, nv), (nu, 1)}
    ok = all(tuple(poles[i - 1, j - 1]) == bs.Pole(i, j).Coord() for i, j in corners)
    ok = ok and u[0][0] == bs.UKnot(1) and u[0][-1] == bs.UKnot(ku)
    ok = ok and v[0][0] == bs.VKnot(1) and v[0][-1] == bs.VKnot(kv)
    ok = ok and _counts_agree(u[1], nu, bs.UDegree(), bs.IsUPeriodic())
    ok = ok and _counts_agree(v[1], nv, bs.VDegree(), bs.IsVPeriodic())
    weights = rows[:, :, 3].copy() if rational else None
    ok = ok and (not rational or weights[nu // 2, nv // 2] == bs.Weight(nu // 2 + 1, nv // 2 + 1))
    return (poles, weights, (u[0], u[1]), (v[0], v[1])) if ok else None
