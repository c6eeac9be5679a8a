"""The band segment computed once a row of rays (:func:`~cadcnc.simulation.tool_sweep.band_row`)
gives every ray of the row the same bits as :func:`~cadcnc.simulation.tool_sweep.swept_ray`,
and is refused where the row's height is not one (a tilted axis, a degenerate move)."""

from __future__ import annotations

import numpy as np

from cadcnc.simulation.tool_sweep import (
    CONSTANTS,
    RAD,
    band_row,
    capsule_of,
    move_constants,
    swept_ray,
)


def constants(p0, p1, axis, radius, length) -> np.ndarray:
    c = np.empty(CONSTANTS)
    move_constants(c, *p0, *p1, *axis, radius, length)
    return c


def rows_agree(c, k, v, heights, across) -> int:
    """Rows of rays along k at each of ``heights`` (the third axis) and every ``across``
    (axis v): assert band_row's capsule equals swept_ray bit for bit; the rows it took."""
    u = 3 - k - v
    taken = 0
    for h in heights:
        o = np.zeros(3)
        o[u], o[v], o[k] = h, across[0], -20.0
        row, s = band_row(o[0], o[1], o[2], k, v, c)
        taken += bool(row)
        for x in across:
            o[v] = x
            want = swept_ray(o[0], o[1], o[2], k, c, -1e3, 1e3)
            if row:
                got = capsule_of(o[0], o[1], o[2], k, *s, c[RAD])
                assert np.array(got).tobytes() == np.array(want).tobytes()
    return taken


def test_band_rows_give_swept_ray_bits_under_a_vertical_axis():
    rng = np.random.default_rng(3)
    up = np.array([0.0, 0.0, 1.0])
    taken = 0
    for _ in range(30):
        p0 = rng.uniform(-2, 2, 3)
        p1 = p0 + rng.uniform(-1, 1, 3) * (1.0, 1.0, 0.3)
        c = constants(p0, p1, up, rng.uniform(0.5, 3), rng.uniform(2, 10))
        heights = np.concatenate([np.linspace(-4, 12, 60), [p0[2], p1[2]]])
        for k, v in ((1, 0), (0, 1)):   # rays along Y or X, the other horizontal axis varying
            taken += rows_agree(c, k, v, heights, np.linspace(-6, 6, 97))
    assert taken > 500                  # most rows above the ball centres are band rows


def test_no_band_row_under_a_tilted_axis_or_across_the_axis():
    tilted = np.array([0.3, 0.0, 1.0]) / np.hypot(0.3, 1.0)
    c = constants(np.zeros(3), np.array([1.0, 0.5, 0.2]), tilted, 1.0, 5.0)
    assert rows_agree(c, 1, 0, np.linspace(-2, 6, 40), np.linspace(-3, 3, 31)) == 0
    up = np.array([0.0, 0.0, 1.0])
    c = constants(np.zeros(3), np.array([1.0, 0.5, 0.2]), up, 1.0, 5.0)
    assert rows_agree(c, 2, 0, np.linspace(-2, 2, 20), np.linspace(-3, 3, 31)) == 0   # along Z
    assert rows_agree(c, 0, 2, np.linspace(-2, 2, 20), np.linspace(-3, 3, 31)) == 0   # Z varies
    plunge = constants(np.zeros(3), np.array([0.0, 0.0, -1.0]), up, 1.0, 5.0)   # along the axis
    assert rows_agree(plunge, 1, 0, np.linspace(-2, 6, 40), np.linspace(-3, 3, 31)) == 0
