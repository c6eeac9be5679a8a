"""docs/img/controller_blend.png: the pencil program of pocket.step with its links at Z 80
streamed on the default machine at 10 000 mm/min with exact corners and with ``--blend``
10 and 20 mm: the link's path (X against Z, the blend cutting its corners) and the feed
against time (the stops at the corners passed).

    .venv/bin/python -m benchmarks.controller.blend_plot
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import cadcnc  # noqa: E402
from cadcnc.controller import Machine, stream_program  # noqa: E402
from cadcnc.ops.stream_steppers import stepper_factory  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "docs" / "img" / "controller_blend.png"
FEED = 10_000.0   # mm/min


def main() -> None:
    part = cadcnc.load_step(ROOT / "fixtures" / "pocket.step")
    program = cadcnc.run(part, cadcnc.Job(cadcnc.Tool(3.0), 1500.0, 0.004, cadcnc.Pencil(),
                                          source=part.source, clearance=80.0))
    machine = Machine.default()
    fig, (path, feed) = plt.subplots(1, 2, figsize=(11, 4))
    for blend in (0.0, 10.0, 20.0):
        s = stream_program(program, machine, stepper_factory(part), feed=FEED, blend=blend)
        seg = np.array([p.segment for p in s.plan.pieces])[s.rows]
        link = s.positions[seg == 2]
        path.plot(link[:, 0], link[:, 2], lw=1.0, label=f"blend {blend:g} mm")
        v = 60.0 * np.linalg.norm(np.diff(s.positions, axis=0), axis=1) / machine.period
        t = machine.period * np.arange(1, len(s.positions))
        feed.plot(t, v, lw=0.8, label=f"blend {blend:g} mm: cycle {s.cycle_time:.3f} s")
        print(f"blend {blend:g} mm: cycle {s.cycle_time:.3f} s, links rounded {sorted(s.rounded)}")
    path.set_xlabel("X mm")
    path.set_ylabel("Z mm")
    path.set_title("the link between the boss and the pocket (Y not shown)", fontsize=8)
    path.set_aspect("equal")
    path.legend(fontsize=7)
    feed.set_xlabel("time s")
    feed.set_ylabel("feed mm/min")
    feed.set_title("feed along the whole program", fontsize=8)
    feed.legend(fontsize=7, loc="upper right")
    fig.suptitle(f"pencil pocket.step, links at Z 80, F {FEED:g}, {machine.source}",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(OUT, dpi=110)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
