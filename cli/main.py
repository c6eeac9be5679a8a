"""Entry point: argparse subcommands; heavy imports happen inside the commands."""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="cadcnc")
    sub = parser.add_subparsers(dest="command", required=True)
    faces = sub.add_parser("faces", help="list faces and concave pairs of a STEP part")
    faces.add_argument("step")
    args = parser.parse_args(argv)
    import cadcnc

    part = cadcnc.load_step(args.step)
    for f in part.faces:
        print(f.number, f.kind)
    print("concave pairs:", part.concave_pairs())
    return 0


if __name__ == "__main__":
    sys.exit(main())
