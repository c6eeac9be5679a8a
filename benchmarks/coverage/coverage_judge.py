"""The judge's verdicts on one pair's concave edges, and coverage of them by cut polylines
(shared by ``pair_coverage.py``, one ``cadcnc path`` run per pair, and ``pencil_coverage.py``,
one ``cadcnc pencil`` run per part).

Positions are those of ``coverage_oracle.py``: every 0.2 mm of each concave edge, at least
9 per edge, no cap unless one is given. Counts: ``feasible`` (the spec's four rules and
reachable from +Z), ``unreachable`` (the spec's rules hold with the shank of length L,
but a shank continued up past the part's top meets it: a sealed void, a high overhang),
``ball`` (the ball fits: feasible, unreachable or only the shank of length L hits).
Lengths mm.
"""

from __future__ import annotations

import collections
import hashlib
import json
import os
from pathlib import Path

import numpy as np

from benchmarks.coverage.coverage_paths import distance_to_polylines
from cadcnc.testing import coverage_oracle, coverage_sewing

COVERED = 5e-3  # mm: a feasible position within this of a cut polyline is covered
CACHE_ENV = "COVERAGE_JUDGE_CACHE"
"""A folder named by this environment variable keeps each pair's verdicts (one JSON file
per part, radius, pair and cap), so that pair_coverage.py and pencil_coverage.py judge a
part once. The key holds the file's size and mtime, VERSION and a digest of the judge's
source (this file, cadcnc/testing/coverage_oracle.py and coverage_sewing.py): any change
to the judge makes a new key."""
VERSION = 2  # of the judge's verdicts (2: `unreachable`)


def judge_digest() -> str:
    """sha1 (12 hex digits) of the judge's source: coverage_oracle.py, coverage_sewing.py
    and this file."""
    h = hashlib.sha1()
    for path in (Path(coverage_oracle.__file__), Path(__file__),
                 Path(coverage_sewing.__file__)):
        h.update(path.read_bytes())
    return h.hexdigest()[:12]


DIGEST = judge_digest()  # at import: the source this process runs


def _cache_file(step: str, faces, radius: float, cap) -> Path | None:
    folder = os.environ.get(CACHE_ENV)
    if not folder:
        return None
    st = os.stat(step)
    name = (f"{Path(step).name}-{st.st_size}-{int(st.st_mtime)}-R{radius:g}-{faces[0]}-"
            f"{faces[1]}-cap{cap}-v{VERSION}-{DIGEST}.json")
    return Path(folder) / name


def judge_pair_cached(step: str, o, faces: tuple[int, int], radius: float,
                      cap: int | None = None) -> dict:
    """:func:`judge_pair`, read from or written to the cache folder when one is set."""
    path = _cache_file(step, faces, radius, cap)
    if path is not None and path.exists():
        return json.loads(path.read_text())
    out = judge_pair(o, faces, radius, cap)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(json.dumps(out))
        os.replace(tmp, path)
    return out


def judge_pair(o, faces: tuple[int, int], radius: float, cap: int | None = None) -> dict:
    """{"edges": [{"edge", "length_mm", "verdicts": {verdict [face]: count},
    "feasible": [p], "index": [sample number of each feasible p], "unreachable": [p],
    "ball": [p]}]} for the pair's concave edges
    (judge ``o``, R' = radius, shank 10 R')."""
    offset, shank = radius, 10.0 * radius
    edges = []
    for e in (e for e in o.concave_edges() if e.faces == tuple(faces)):
        counts = collections.Counter()
        kinds: dict[str, list] = {"feasible": [], "unreachable": [], "ball": [], "index": []}
        for k, t in enumerate(o.samples(e, cap)):
            v = o.judge(e, t, offset, shank)
            counts[v["verdict"] if not v["face"] else f"{v['verdict']} {v['face']}"] += 1
            if v["verdict"] in ("feasible", "unreachable"):
                kinds[v["verdict"]].append(v["p"])
            if v["verdict"] == "feasible":
                kinds["index"].append(k)
            if v["verdict"] in ("feasible", "unreachable", "ball"):
                kinds["ball"].append(v["p"])
        edges.append({"edge": e.index, "faces": list(faces), "length_mm": round(e.length, 4),
                      "verdicts": dict(counts), **kinds})
    return {"edges": edges}


def covered(points: list, polylines: list) -> np.ndarray:
    """Whether each point (k, 3) lies within COVERED of a polyline, (k,) bool."""
    if not points:
        return np.zeros(0, bool)
    if not polylines:
        return np.zeros(len(points), bool)
    return distance_to_polylines(np.asarray(points, float), polylines) <= COVERED


def missed_runs(points: list, index: list, hit: np.ndarray) -> list[dict]:
    """Runs of uncovered feasible positions along an edge, consecutive in sample order
    (``index``): a missed stretch each, {"n", "from", "to"} (mm)."""
    runs, start = [], None
    for k in range(len(points) + 1):
        bad = k < len(points) and not hit[k]
        if start is not None and (not bad or index[k] != index[k - 1] + 1):
            runs.append({"n": k - start, "from": [round(float(x), 4) for x in points[start]],
                         "to": [round(float(x), 4) for x in points[k - 1]]})
            start = None
        if bad and start is None:
            start = k
    return runs
