"""cadcnc's benchmarks, run from the repository's root (see benchmarks/README.md).

    .venv/bin/python -m benchmarks perf [--quick | --full]   # docs/performance.md's tables

Subpackages: ``kernel`` (the stepper, its evaluators, trim grids, guard and gate costs),
``coverage`` (the independent judge and coverage of ``path`` and ``pencil``),
``finishing`` (guide-surface finishing against OpenCAMLib). Not installed with cadcnc.
"""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "fixtures"
