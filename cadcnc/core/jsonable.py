"""Python and numpy values as JSON-ready objects: one converter for every JSON cadcnc writes."""

from __future__ import annotations

import math

import numpy as np

NONFINITE_STRINGS = {math.inf: "Infinity", -math.inf: "-Infinity"}


def plain(obj, nonfinite_as_strings: bool = False):
    """``obj`` with numpy scalars and arrays as Python numbers and lists, tuples as lists.

    JSON has no literal for nan and inf: they become None (null), or with
    ``nonfinite_as_strings`` the strings "NaN", "Infinity", "-Infinity" (which
    ``float()`` reads back).
    """
    if isinstance(obj, dict):
        return {str(k): plain(v, nonfinite_as_strings) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v, nonfinite_as_strings) for v in obj]
    if isinstance(obj, np.ndarray):
        return plain(obj.tolist(), nonfinite_as_strings)
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        if math.isfinite(x):
            return x
        if not nonfinite_as_strings:
            return None
        return "NaN" if math.isnan(x) else NONFINITE_STRINGS[x]
    return obj
