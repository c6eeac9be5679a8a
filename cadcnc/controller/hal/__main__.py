"""``python -m cadcnc.controller.hal STREAM --period S --max-velocity X Y Z ...``: HAL in the loop.

A stream file's front end (``cadcnc stream --hal`` runs a program's planned stream). Exit
0 when the run completed with no underrun within the program and no clipped sample; 6 when
it completed but some were (as ``cadcnc stream --hal``); 2 for an unreadable stream; 1 when
HAL could not start or run; 130 on Ctrl-C (HAL unloaded first).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...core.errors import EXIT_PARTIAL, CadcncError
from ...core.interrupts import ctrl_c_interrupts
from .loop import run_hal_loop, summary
from .session import HalError, hal_available


@dataclass(frozen=True)
class _Limits:
    """The attributes run_hal_loop reads from a machine (s, mm/s, mm/s², mm/s³)."""

    period: float
    max_velocity: tuple[float, float, float]
    max_acceleration: tuple[float, float, float]
    max_jerk: tuple[float, float, float] = (float("inf"),) * 3


def main(argv: list[str] | None = None) -> int:
    """Run a stream through HAL and print what it executed; the exit code as above."""
    ap = argparse.ArgumentParser(prog="python -m cadcnc.controller.hal", description=__doc__)
    ap.add_argument("stream", type=Path, help=".npy (N, 3) or .txt (X Y Z per line), mm")
    ap.add_argument("--period", type=float, default=0.001, help="servo period, s")
    ap.add_argument("--max-velocity", type=float, nargs=3, default=(1e20,) * 3,
                    metavar=("X", "Y", "Z"), help="mm/s")
    ap.add_argument("--max-acceleration", type=float, nargs=3, default=(1e20,) * 3,
                    metavar=("X", "Y", "Z"), help="mm/s²")
    ap.add_argument("--wide", action="store_true", help="limit3 at 1e20: pass everything")
    ap.add_argument("--executed", type=Path, help="write executed positions here (.npy)")
    args = ap.parse_args(argv)
    ctrl_c_interrupts()   # as the cadcnc command: even when started with Ctrl-C ignored
    try:
        missing = hal_available()
        if missing:
            raise HalError(f"HAL tools {missing} (install linuxcnc-uspace)")
        machine = _Limits(args.period, tuple(args.max_velocity), tuple(args.max_acceleration))
        result = run_hal_loop(args.stream, machine, limits="wide" if args.wide else "machine",
                              on_started=lambda: print("HAL running", file=sys.stderr,
                                                       flush=True))
    except CadcncError as e:
        print(f"cadcnc: error: {e}", file=sys.stderr)
        return e.exit_code
    print(summary(result))
    if args.executed:
        np.save(args.executed, result.executed)
    return 0 if result.underruns == 0 and result.clipped == 0 else EXIT_PARTIAL


if __name__ == "__main__":
    sys.exit(main())
