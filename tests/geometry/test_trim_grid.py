"""The trim grid answers exactly as FaceSurface.classify (FClass2d), mostly without it.

Contract: ``TrimGrid.classify(u, w) == FaceSurface.classify(u, w)`` for every (u, w),
"boundary" included: MIXED cells defer to the same FClass2d call, so the only possible
disagreement is a cell wrongly labelled INSIDE or OUTSIDE, and any disagreement fails.
"""

from __future__ import annotations

from pathlib import Path

import numba
import numpy as np
import pytest
from OCP.BRepAdaptor import BRepAdaptor_Curve2d
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

import cadcnc
from cadcnc.geometry import trim_grid
from cadcnc.geometry.trim_grid import CELL_MIXED, TrimGrid, classifier_tolerance
from cadcnc.interp.kernel import trim_lookup
from cadcnc.interp.kernel.trim_lookup import lookup, wrap

pytestmark = pytest.mark.slow  # over about 5 s a test (pyproject.toml)

FIXTURES = Path(__file__).resolve().parents[2] / "fixtures"
STEPS = sorted(FIXTURES.glob("*.step"))
N_RANDOM = 10_000
N_SHARE = 3_000  # of the random points, for the O(1) share
MIXED_CHECKS = 100  # per face: MIXED points on which TrimGrid.classify defers to FClass2d


def box_points(face, rng, n: int) -> np.ndarray:
    """(n, 2) uniform over the face's (u, w) box enlarged 5 % each side, plus 1 % far out."""
    (u0, u1), (w0, w1) = face.u_range, face.w_range
    du, dw = u1 - u0, w1 - w0
    pts = np.column_stack([rng.uniform(u0 - 0.05 * du, u1 + 0.05 * du, n),
                           rng.uniform(w0 - 0.05 * dw, w1 + 0.05 * dw, n)])
    far = n // 100
    pts[:far] = np.column_stack([rng.uniform(u0 - 10 * du, u1 + 10 * du, far),
                                 rng.uniform(w0 - 10 * dw, w1 + 10 * dw, far)])
    return pts


def boundary_points(face, rng, per_edge: int = 24) -> np.ndarray:
    """Pcurve samples offset by tiny amounts: multiples of the classifier tolerance and
    fractions of the box, in random directions; shape (k, 2)."""
    tol = classifier_tolerance(face)
    size = max(face.u_range[1] - face.u_range[0], face.w_range[1] - face.w_range[0])
    steps = np.array([0.0, 0.5 * tol, tol, 2 * tol, 10 * tol, 1e-7 * size, 1e-4 * size,
                      1e-2 * size])
    samples = []
    edges = TopExp_Explorer(face.topods, TopAbs_EDGE)
    while edges.More():
        curve = BRepAdaptor_Curve2d(TopoDS.Edge_s(edges.Current()), face.topods)
        for t in np.linspace(curve.FirstParameter(), curve.LastParameter(), per_edge):
            samples.append(curve.Value(float(t)).Coord())
        edges.Next()
    base = np.repeat(np.array(samples), len(steps), axis=0)
    angle = rng.uniform(0, 2 * np.pi, len(base))
    radius = np.tile(steps, len(samples))
    return base + radius[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])


@numba.njit(nogil=True)  # not cached: a cached caller keeps its copy of lookup when it changes
def lookup_many(codes, fine, u0, w0, du, dw, nu, nw, u, w):  # pragma: no cover (compiled)
    """``lookup`` (the kernel's reader, which ``TrimGrid.cell`` calls) at each of the (n,)
    window points (u, w): (n,) int64 cell labels, compiled so that the 10^4-point sweep
    spends its time in FClass2d, the reference, not in Python."""
    out = np.empty(len(u), np.int64)
    for k in range(len(u)):
        out[k] = lookup(codes, fine, u0, w0, du, dw, nu, nw, u[k], w[k])
    return out


def windows_of(grid, pts: np.ndarray) -> np.ndarray:
    """(n, 2) points moved into the grid's window: ``TrimGrid.to_window`` on arrays (the
    same float operations; checked against it point by point below)."""
    us, pu, ws, pw = grid.window
    return np.column_stack([us + np.remainder(pts[:, 0] - us, pu) if pu else pts[:, 0],
                            ws + np.remainder(pts[:, 1] - ws, pw) if pw else pts[:, 1]])


_parts: dict = {}


def part_of(path: Path):
    """The fixture's Part, loaded once per module (the grids are built anew each test)."""
    if path not in _parts:
        _parts[path] = cadcnc.load_step(path)
    return _parts[path]


@pytest.mark.parametrize("path", STEPS, ids=[p.stem for p in STEPS])
def test_grid_agrees_with_fclass2d_on_every_face(path):
    """Every face of every fixture: 10^4 random points (plus pcurve-hugging ones), each
    classified by the grid and, wherever the grid's answer is its own, by FClass2d
    (``FaceSurface.classify``): 0 disagreements.

    The grid's answer is its cell's label read by ``lookup`` (compiled, over all points at
    once); that this is ``TrimGrid.classify`` is checked point by point on the first 300
    points (``to_window``, ``cell`` and ``classify`` against the arrays). On a MIXED cell
    ``TrimGrid.classify`` asks FClass2d itself: the same classifier object as
    ``FaceSurface.classify`` (asserted) on the same wrapped point, so it cannot disagree
    there; that deferral is called on MIXED_CHECKS random MIXED points per face (each such
    call costs ~25 us, as much as the reference's own call)."""
    part = part_of(path)
    rng = np.random.default_rng(7)
    bad, o1 = [], []
    for face in part.faces:
        grid = TrimGrid.build(face)
        assert not grid.stats["exact_only"] and grid.stats["suspect"] == 0, (face, grid.stats)
        assert grid.labels.dtype == np.int8 and grid.labels.size <= 2 * 65536
        pts = np.vstack([box_points(face, rng, N_RANDOM), boundary_points(face, rng)])
        windowed = windows_of(grid, pts)
        codes = lookup_many(*grid.kernel_args, windowed[:, 0].copy(), windowed[:, 1].copy())
        mixed = codes == CELL_MIXED
        us, ws = pts[:, 0].tolist(), pts[:, 1].tolist()
        at = np.nonzero(mixed)[0]
        pick = np.random.default_rng(face.number)  # the points drawn stay rng's as before
        checked = pick.choice(at, min(MIXED_CHECKS, len(at)), replace=False).tolist()
        # the reference where an answer is compared: every point the grid answers, the
        # MIXED points checked, the first 300 (compared with TrimGrid.classify below); on
        # the other MIXED points the grid's answer is FClass2d's own call, not compared
        judged = ~mixed
        judged[checked] = True
        judged[:300] = True
        expected = [face.classify(u, w) if j else None
                    for u, w, j in zip(us, ws, judged.tolist())]
        got = [trim_grid._CODE_STATE.get(c, e) for c, e in zip(codes.tolist(), expected)]
        assert grid._fc is face._classifier
        for k in checked:
            got[k] = grid.classify(us[k], ws[k])
        bad += [(face.number, us[k], ws[k], e, g)
                for k, (e, g) in enumerate(zip(expected, got)) if g != e]
        o1.append(np.mean(~mixed[:N_SHARE]))
        # the arrays are TrimGrid's own answers, and the kernel reads the same cells
        up, pu, wp, pw = grid.window
        for k, ((u, w), (uw, ww)) in enumerate(zip(pts[:300].tolist(),
                                                   windowed[:300].tolist())):
            assert grid.to_window(u, w) == (uw, ww)
            assert (wrap(u, up, pu), wrap(w, wp, pw)) == (uw, ww)
            assert lookup(*grid.kernel_args, uw, ww) == grid.cell(uw, ww) == codes[k]
            assert grid.classify(u, w) == got[k]
    assert bad == [], f"{len(bad)} disagreements, first: {bad[:5]}"
    # the O(1) path answers almost everything (a regression to 'all MIXED' fails here)
    assert min(o1) > 0.85, o1
    assert np.mean(np.array(o1) > 0.90) >= 0.9, o1


def test_wrap_moves_by_whole_periods():
    assert wrap(7.0, 1.0, 5.0) == 2.0
    assert wrap(-0.5, 0.0, 2.0) == 1.5
    assert wrap(123.0, 1.0, 0.0) == 123.0  # not periodic


def test_lookup_clamps_and_defers_on_nonfinite():
    grid = np.array([[0, 1], [2, 1]], dtype=np.int64)
    args = (grid, np.zeros(0, np.int64), 0.0, 0.0, 1.0, 1.0, 2, 2)
    assert lookup(*args, 0.5, 1.5) == 1
    assert lookup(*args, 1.5, 0.5) == 2
    assert lookup(*args, -5.0, -5.0) == 0  # beyond the grid: the nearest border cell
    assert lookup(*args, 99.0, 99.0) == 1
    for bad in (float("nan"), float("inf"), -float("inf")):
        assert lookup(*args, bad, 0.5) == trim_lookup.CELL_MIXED


def test_lookup_reads_sub_cells():
    """A MIXED cell split in 2 x 4 sub-cells (code 3 + offset of Ru, Rw, labels)."""
    codes = np.array([[0, 3]], dtype=np.int64)
    fine = np.array([2, 4, 0, 0, 1, 2, 1, 1, 1, 0], dtype=np.int64)
    args = (codes, fine, 0.0, 0.0, 1.0, 1.0, 1, 2)
    assert lookup(*args, 0.5, 0.5) == 0  # an unsplit cell
    assert [lookup(*args, 0.25, 1.0 + b / 4 + 0.1) for b in range(4)] == [0, 0, 1, 2]
    assert [lookup(*args, 0.75, 1.0 + b / 4 + 0.1) for b in range(4)] == [1, 1, 1, 0]
    assert lookup(*args, 9.0, 9.0) == 0  # clamped into the last sub-cell


@pytest.mark.parametrize("name", ["crossing_cylinders", "sphere_cylinder", "bspline_boss"])
def test_sub_cells_answer_most_points_of_mixed_cells(name):
    """Points drawn in the MIXED cells (seams and trim bands) are mostly answered by the
    sub-cells, and every answer equals FClass2d's (the sub-cells' labels are exact too)."""
    part, rng = part_of(FIXTURES / f"{name}.step"), np.random.default_rng(3)
    for face in part.faces[:2]:
        grid = TrimGrid.build(face)
        coarse = TrimGrid.build(face, sub_cells=1)
        assert coarse.fine.size == 0 and np.array_equal(coarse.labels, grid.labels)
        cells = np.argwhere(grid.labels == CELL_MIXED)
        pick = cells[rng.integers(0, len(cells), 2000)] + rng.uniform(0, 1, (2000, 2))
        pts = np.column_stack([grid.u0 + pick[:, 0] * grid.du, grid.w0 + pick[:, 1] * grid.dw])
        answered = 0
        for u, w in pts.tolist():
            code = grid.cell(u, w)
            assert coarse.cell(u, w) == CELL_MIXED
            if code != CELL_MIXED:
                answered += 1
                expected = face.classify(*face.wrap(u, w))
                assert trim_grid._CODE_STATE[code] == expected, (face.number, u, w)
        assert answered > 0.8 * len(pts), (face.number, answered, grid.stats)
