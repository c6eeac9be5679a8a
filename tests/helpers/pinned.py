"""The pinned fixture pairs (fixtures/build_pinned_paths.py): every concave pair of the
fixtures with the radius it is pinned at, and the computation that pinned it."""

from __future__ import annotations

import sys

from helpers.fixtures import FIXTURES

sys.path.insert(0, str(FIXTURES))
from build_pinned_paths import compute, pinned_cases, radius_for  # noqa: E402,F401

CASES = list(pinned_cases())
"""(key, fixture name, face i, face j) of every pinned pair."""
