"""A tangency search with no answer gives up once its residual stops falling.

Two concentric cylinders (radii 10 and 30, axis Z): a ball of R' 3 touching both would
have its centre at radius 13 and 33 at once, so no position exists (the residual, the
largest coordinate gap, is at least 20 / sqrt(2) mm). Newton hovers above that, its damped
steps halved to their floor; it used to take all 60 steps (17 ms a search on bug27453's
corners); it now stops after STALLS steps without progress. A search that has an answer
is unaffected (crossing cylinders: tests/interp/test_interpolator.py; every fixture's
and shared part's program the same).
"""

from __future__ import annotations

import pytest
from test_interpolator import AnalyticCylinder

from cadcnc.core.errors import StartPointError
from cadcnc.interp.tangency import solve_tangency


class Counted(AnalyticCylinder):
    """The cylinder, counting its evaluations."""

    calls = 0

    def derivative_tuples(self, u, w):
        Counted.calls += 1
        return super().derivative_tuples(u, w)


def test_no_position_gives_up_after_the_residual_stalls():
    Counted.calls = 0
    inner, outer = Counted(10.0, (0, 0, 1), (1, 0, 0)), Counted(30.0, (0, 0, 1), (1, 0, 0))
    with pytest.raises(StartPointError) as err:
        solve_tangency(inner, outer, (3.0, 3.0), (0.0, 0.0), (0.1, 0.0),
                       anchor=(20.0, 0.0, 0.0), direction=(0, 0, 1))
    steps = int(str(err.value).split(" in ")[1].split()[0])
    least = float(str(err.value).split("least residual ")[1].split()[0])
    assert steps < 30, str(err.value)
    assert least > 10.0   # (the residual is the largest coordinate gap: 20 / sqrt(2) at best)
    assert Counted.calls < 600, Counted.calls
