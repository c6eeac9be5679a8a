"""What a part's edge classification costs here and in a worker (issue 24).

``part.adjacency`` on a freshly read part (the caller's cost), then what a worker pays:
``part_from_blob(*part_blob(part))`` through pickle and its ``.adjacency`` (taken from
the blob where it carries one, else classified again). Prints one JSON line per repeat
with the load average; run it with another checkout's interpreter to compare
(``/work/main/.venv/bin/python benchmarks/pace/bench_adjacency.py``: it imports the
cadcnc that interpreter has)::

    .venv/bin/python -m benchmarks.pace.bench_adjacency [PART.stp] [--repeat N]
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import time

import cadcnc
from cadcnc.geometry.part_bytes import part_blob, part_from_blob

DEFAULT_PART = "/work/shared/parts/r0901_ec.stp"


def measure(path: str) -> dict:
    """Seconds of the caller's classification and of a worker's rebuild + adjacency."""
    load = os.getloadavg()[0]
    part = cadcnc.load_step(path)
    t0 = time.perf_counter()
    edges = sum(len(v) for v in part.adjacency.values())
    t1 = time.perf_counter()
    data = pickle.dumps(part_blob(part))
    t2 = time.perf_counter()
    rebuilt = part_from_blob(*pickle.loads(data))
    t3 = time.perf_counter()
    rebuilt.adjacency
    t4 = time.perf_counter()
    return dict(cadcnc=os.path.dirname(cadcnc.__file__), part=os.path.basename(path),
                edges=edges, adjacency_s=round(t1 - t0, 3), blob_s=round(t2 - t1, 3),
                blob_mb=round(len(data) / 1e6, 2), rebuild_s=round(t3 - t2, 3),
                rebuilt_adjacency_s=round(t4 - t3, 3), worker_s=round(t4 - t2, 3),
                load_before=round(load, 2), load_after=round(os.getloadavg()[0], 2))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("part", nargs="?", default=DEFAULT_PART)
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args(argv)
    for _ in range(args.repeat):
        print(json.dumps(measure(args.part)), flush=True)


if __name__ == "__main__":
    main()
