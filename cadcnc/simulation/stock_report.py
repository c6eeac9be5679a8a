"""The simulation's report: material left per face, gouges, collisions (docs/simulate.md).

JSON fields (lengths mm, areas mm^2): ``faces`` [{"face", "max_left_mm", "p99_left_mm",
"mean_left_mm", "area_over_mm2", "area_mm2", "gouges", "deepest_gouge_mm"}],
``gouges`` [{"face", "depth_mm", "at", "count"}] (one per cluster, deepest first),
``collisions`` [{"move", "program", "at"}], ``resolution_mm``, ``stock``, and
``threshold_mm``, ``gouge_limit_mm``, ``moves``, ``rays``, ``programs``, ``exit_code``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.errors import EXIT_GOUGE, EXIT_OK
from .compare import Samples
from .grid import rays
from .stock import Stock

MAX_REFINED = 4000   # suspected gouges measured by OCCT, deepest estimates first
MAX_GOUGES = 50      # gouge clusters listed


@dataclass
class SimulationReport:
    """What :func:`~cadcnc.simulation.simulator.simulate` found (module doc); ``stock`` and
    ``samples`` keep the arrays the pictures draw."""

    data: dict
    stock: Stock
    samples: Samples
    gouge_points: np.ndarray       # (g, 3) refined gouge points, mm
    gouge_depths: np.ndarray       # (g,) mm
    timing: dict = field(default_factory=dict)

    @property
    def exit_code(self) -> int:
        return EXIT_GOUGE if self.data["gouges"] or self.data["collisions"] else EXIT_OK

    def to_dict(self) -> dict:
        return {**self.data, "exit_code": self.exit_code,
                "timing_s": {k: round(v, 3) for k, v in self.timing.items()}}

    def summary(self) -> str:
        d = self.data
        worst = max((f["max_left_mm"] for f in d["faces"] if f["max_left_mm"] is not None),
                    default=0.0)
        lines = [f"simulated {d['moves']} moves of {len(d['programs'])} program(s) on "
                 f"{d['rays']} rays at {d['resolution_mm']:g} mm: most material left "
                 f"{worst:.4f} mm; {len(d['gouges'])} gouge(s), {len(d['collisions'])} "
                 f"collision(s)"]
        lines += [_shank_line([p.get("shank_mm") for p in d["programs"]])]
        lines += [f"  gouge: face {g['face']} {g['depth_mm']:.4f} mm deep at "
                  f"({', '.join(f'{c:.3f}' for c in g['at'])})" for g in d["gouges"][:10]]
        lines += [f"  collision: move {c['move']} (a rapid of program {c['program']}) "
                  f"meets stock at ({', '.join(f'{v:.3f}' for v in c['at'])})"
                  for c in d["collisions"][:10]]
        return "\n".join(lines)


def _shank_line(shanks: list) -> str:
    """Which shank the simulation swept: mm above the ball centre per program (None: up to
    a G-code program's highest point)."""
    if len(set(shanks)) == 1 and shanks[0] is not None:
        return (f"  shank {shanks[0]:g} mm above the ball centre (a cadcnc program's "
                "tool's unless --shank MM gives another)")
    return "  shank above the ball centre: " + ", ".join(
        f"program {i + 1} " + ("up to its highest point" if s is None else f"{s:g} mm")
        for i, s in enumerate(shanks))


def weighted_quantile(values: np.ndarray, weights: np.ndarray, q: float) -> float:
    """The ``q`` quantile of ``values`` weighted by ``weights`` (areas)."""
    order = np.argsort(values)
    cum = np.cumsum(weights[order])
    return float(values[order][min(np.searchsorted(cum, q * cum[-1]), len(cum) - 1)])


def refine(samples: Samples, distance, limit: float, deflection: float):
    """(points (g, 3), depths (g,), faces (g,)) of the samples that took more than
    ``limit`` mm of the part, by OCCT's exact distance of the stock's inner end."""
    suspect = np.flatnonzero(samples.left < -(limit - deflection))
    suspect = suspect[np.argsort(samples.left[suspect])][:MAX_REFINED]
    pts = samples.inner[suspect]
    finite = np.all(np.isfinite(pts), axis=1)
    pts, suspect = pts[finite], suspect[finite]
    if not len(pts):
        return np.zeros((0, 3)), np.zeros(0), np.zeros(0, int)
    depth, face = distance(pts)
    deep = depth > limit
    face = np.where(face > 0, face, samples.face[suspect])
    return pts[deep], depth[deep], face[deep]


def clusters(points, depths, faces, reach: float) -> list[dict]:
    """One entry per face and connected region (points chained within ``reach`` mm), at
    its deepest point, deepest first."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    if not len(points):
        return []
    pairs = cKDTree(points).query_pairs(reach, output_type="ndarray")
    pairs = pairs[faces[pairs[:, 0]] == faces[pairs[:, 1]]]
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])),
                       shape=(len(points), len(points)))
    _, label = connected_components(graph, directed=False)
    out = []
    for c in np.unique(label):
        members = np.flatnonzero(label == c)
        i = members[np.argmax(depths[members])]
        out.append({"face": int(faces[i]), "depth_mm": float(depths[i]),
                    "at": [float(v) for v in points[i]], "count": int(len(members))})
    return sorted(out, key=lambda g: -g["depth_mm"])


def build_report(part, runs, stock: Stock, samples: Samples, stock_desc: dict, distance,
                 limit: float, deflection: float, threshold: float) -> SimulationReport:
    """The :class:`SimulationReport` of a simulation (module doc)."""
    points, depths, gface = refine(samples, distance, limit, deflection)
    gouges = clusters(points, depths, gface, 2.0 * stock.res * np.sqrt(3.0))
    faces = []
    for n in range(1, len(part) + 1):
        on = samples.face == n
        left, area = np.clip(samples.left[on], 0.0, None), samples.area[on]
        mine = gface == n
        entry = {"face": n, "max_left_mm": None, "p99_left_mm": None, "mean_left_mm": None,
                 "area_over_mm2": 0.0, "area_mm2": float(area.sum()),
                 "gouges": int(mine.sum()),
                 "deepest_gouge_mm": float(depths[mine].max()) if mine.any() else 0.0}
        if on.any():
            entry.update(max_left_mm=float(left.max()),
                         p99_left_mm=weighted_quantile(left, area, 0.99),
                         mean_left_mm=float((left * area).sum() / area.sum()),
                         area_over_mm2=float(area[left > threshold].sum()))
        faces.append(entry)
    moves = stock.moves
    data = {
        "format": "cadcnc-simulation", "version": 1,
        "part": str(part.source), "resolution_mm": stock.res,
        "stock": {**stock_desc, "lo": stock.lo.tolist(), "hi": stock.hi.tolist()},
        "programs": [{"name": r.name, "radius_mm": r.radius, "axis": r.axis.tolist(),
                      "shank_mm": r.shank, "moves": int((moves.run == i).sum())}
                     for i, r in enumerate(runs)],
        "moves": len(moves), "rays": rays(stock.lo, stock.hi, stock.res),
        "threshold_mm": threshold, "gouge_limit_mm": limit,
        "faces": faces, "gouges": gouges[:MAX_GOUGES],
        "collisions": [{"move": c.move + 1, "program": c.run + 1,
                        "at": [float(v) for v in c.at]} for c in stock.collisions],
    }
    return SimulationReport(data, stock, samples, points, depths)
