"""fixtures/six_pockets.step (fixtures/build_setup_fixtures.py): a pocket on each side of a
block, each corner reachable only along its own tool axis; its facts and the judges of a
program written in a setup's work coordinates."""

from __future__ import annotations

import json
import re

import numpy as np

from cadcnc.testing.occt import occt_distance
from helpers.fixtures import FIXTURES

STEP = FIXTURES / "six_pockets.step"
FACTS = json.loads((FIXTURES / "setup_fixtures.json").read_text())
R = FACTS["radius"]
SHANK = 10 * R
GOUGE = 1e-3      # mm: the default gouge limit
DIGITS = 1e-4     # mm: the G-code's 4 decimals (rounding 5e-5 per coordinate)
AXES = {"+X": (1, 0, 0), "-X": (-1, 0, 0), "+Y": (0, 1, 0), "-Y": (0, -1, 0),
        "+Z": (0, 0, 1), "-Z": (0, 0, -1)}


def written_transform(ngc: str) -> tuple[np.ndarray, np.ndarray]:
    """(R (3, 3), work zero (3,)) as the G-code's comments state them."""
    zero = re.search(r"work zero at part \[([^\]]*)\] mm", ngc)
    rows = re.search(r"R rows \[([^\]]*)\]", ngc)
    assert zero and rows, ngc[:600]
    r = np.array([[float(v) for v in row.split()] for row in rows.group(1).split(";")])
    return r, np.array([float(v) for v in zero.group(1).split(",")])


def distance(shape, a, b=None) -> float:
    """OCCT's distance from point a (or segment a-b) to ``shape``, mm."""
    return occt_distance(a, shape, to=b)


def face_distance(part, n: int, p) -> float:
    """OCCT's distance from p to face n of ``part``, mm."""
    return distance(part.face(n).topods, p)
