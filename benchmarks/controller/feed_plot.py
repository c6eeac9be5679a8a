"""docs/img/controller_feed.png: programmed and planned feed against arc length beside the
time-optimal v/a bound (TOPP-RA, benchmarks/controller/bound.py), and the figures of
docs/controller.md (cycle time, bound, ratio, periods, largest share of each limit).

    .venv/bin/python benchmarks/controller/feed_plot.py
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks.controller.stream_cost import programs
from cadcnc.controller import Machine, stream_program  # noqa: E402
from cadcnc.controller.pieces import constant_speed  # noqa: E402
from cadcnc.ops.stream_steppers import stepper_factory  # noqa: E402
from cadcnc.testing.topp_bound import bound_feed, va_bound

OUT = Path(__file__).resolve().parents[2] / "docs" / "img" / "controller_feed.png"


def main() -> None:
    machine = Machine.default()
    fig, axes = plt.subplots(3, 2, figsize=(11, 8), sharey="row")
    for row, (name, part, program) in zip(axes, programs()):
        for ax, feed in zip(row, (None, 10_000.0)):
            s = stream_program(program, machine, stepper_factory(part), feed=feed)
            x = s.positions
            step = np.linalg.norm(np.diff(x, axis=0), axis=1)
            arc = np.r_[0.0, np.cumsum(step)]
            ax.plot(arc[1:], 60.0 * step / machine.period, lw=0.8, label="planned")
            at, prog = 0.0, []
            for p in s.plan.pieces:
                v = 60.0 * constant_speed(p, machine)
                prog += [(at, v), (at + p.length, v)]
                at += p.length
            prog = np.array(prog)
            ax.plot(prog[:, 0], prog[:, 1], lw=0.8, ls="--", label="programmed")
            bs, bv = bound_feed(program, machine, feed or program.job.feed)
            ax.plot(bs, 60.0 * bv, lw=0.8, ls=":", color="k",
                    label="time-optimal v/a bound (TOPP-RA)")
            sm = s.summary()
            worst = {k: max(sm[f"max_{k}_share"].values()) for k in
                     ("velocity", "acceleration", "jerk")}
            f = feed or program.job.feed
            bound = va_bound(program, machine, f)
            ax.set_title(f"{name}, F {f:g}: {sm['cycle_time_s']:.2f} s = "
                         f"{sm['cycle_time_s'] / bound:.3f} x the bound {bound:.2f} s "
                         f"(programmed {sm['programmed_time_s']:.2f} s)", fontsize=8)
            ax.set_ylim(0, 1.15 * 60 * np.linalg.norm(machine.max_velocity[:2]))
            ax.legend(fontsize=7, loc="upper right")
            print(f"| {name} | {f:g} | {sm['cycle_time_s']:.3f} | {bound:.3f} "
                  f"| {sm['cycle_time_s'] / bound:.3f} | {sm['programmed_time_s']:.3f} "
                  f"| {sm['periods']} | {worst['velocity']:.3f} | {worst['acceleration']:.3f} "
                  f"| {worst['jerk']:.3f} |")
        row[0].set_ylabel("feed mm/min")
    for ax in axes[-1]:
        ax.set_xlabel("arc length along the program (cuts and links), mm")
    fig.suptitle(f"Feed planned to {machine.source}", fontsize=9)
    fig.tight_layout()
    OUT.parent.mkdir(exist_ok=True)
    fig.savefig(OUT, dpi=110)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
