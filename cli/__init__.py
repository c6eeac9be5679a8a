"""cadcnc's command line (installed as the ``cadcnc`` console script)."""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    """Run the command line; Ctrl-C while it starts up is exit 130 too, not a traceback."""
    try:
        from .app import main as run  # inside: Ctrl-C during this import is caught
    except KeyboardInterrupt:
        print("cadcnc: interrupted", file=sys.stderr)
        return 130
    return run(argv)


__all__ = ["main"]
