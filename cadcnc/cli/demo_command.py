"""``cadcnc demo``: the main job on the bundled part, verified, with every output
(:func:`cadcnc.pipeline.demo.run_demo`)."""

from __future__ import annotations

from cadcnc.pipeline.demo import run_demo

from .feedback import progress


def demo(args) -> int:
    return run_demo(args.out, (lambda *a: None) if args.quiet else print,
                    progress(args, "demo"))
