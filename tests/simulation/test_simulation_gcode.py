"""Foreign G-code read through LinuxCNC's rs274: straight moves, arcs in three planes
(chords within 0.1 um of the arc), inch programs, errors named."""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.core.errors import InputError
from cadcnc.io.gcode_reader import CHORD, gcode_moves
from helpers.marks import needs_rs274

pytestmark = needs_rs274


def read(tmp_path, text: str):
    f = tmp_path / "p.ngc"
    f.write_text(text)
    return gcode_moves(f)


def test_moves_arcs_and_units(tmp_path):
    pts, rapid = read(tmp_path, "G21 G90 G17\nG0 X0 Y0 Z10\nG1 Z-1 F100\nG1 X10\n"
                                "G2 X20 Y0 I5 J0\nG18 G3 X30 Z-1 I5 K0\nG20 G1 X1.5\nM2\n")
    assert not rapid.any() and len(rapid) == len(pts) - 1   # from the first G0's end
    assert np.allclose(pts[:3], [(0, 0, 10), (0, 0, -1), (10, 0, -1)])
    xy = pts[3:np.flatnonzero(np.isclose(pts[:, 0], 20) & np.isclose(pts[:, 1], 0))[0] + 1]
    radii = np.hypot(xy[:, 0] - 15, xy[:, 1])
    assert np.allclose(radii, 5, atol=1e-9) and (xy[1:-1, 1] > 0).all()   # G2 from X10: +Y
    mids = 0.5 * (xy[1:] + xy[:-1])                     # chords within CHORD of the arc
    assert (5 - np.hypot(mids[:, 0] - 15, mids[:, 1])).max() <= CHORD + 1e-12
    xz = pts[len(xy) + 2:-1]
    assert np.allclose(np.hypot(xz[:, 0] - 25, xz[:, 2] + 1), 5, atol=1e-9)
    # G20: inches, printed by rs274 with 4 decimals (1e-4 in = 2.5 um)
    assert np.allclose(pts[-1], (1.5 * 25.4, 0, -1), atol=1.3e-3)


def test_errors_name_the_file(tmp_path):
    with pytest.raises(InputError, match="p.ngc: rs274 could not read"):
        read(tmp_path, "G1 X10 F100 Q\nM2\n")
    with pytest.raises(InputError, match="no such file"):
        gcode_moves(tmp_path / "missing.ngc")
