"""One meaning per file name: no two modules of ``cadcnc/`` share a basename, but those
allowed below, each with its reason (issue 38)."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "cadcnc"

ALLOWED = {
    "__init__.py": "a package's own module: Python's name",
    "__main__.py": "``python -m`` of a package: Python's name",
}


def basenames() -> dict[str, list[str]]:
    """Every basename of a module under cadcnc/ and the modules that have it."""
    out = defaultdict(list)
    for path in PKG.rglob("*.py"):
        if "__pycache__" not in path.parts:
            out[path.name].append(str(path.relative_to(PKG)))
    return out


def test_no_two_modules_share_a_name_unless_allowed():
    shared = {name: sorted(paths) for name, paths in basenames().items() if len(paths) > 1}
    assert set(shared) <= set(ALLOWED), {n: p for n, p in shared.items() if n not in ALLOWED}


def test_every_allowance_is_still_needed():
    names = basenames()
    assert not [n for n in ALLOWED if len(names.get(n, ())) < 2]
