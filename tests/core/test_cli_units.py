"""Quantities typed on the command line: periods need a unit, lengths are mm."""

from __future__ import annotations

import pytest

from cadcnc.core.errors import InputError
from cadcnc.core.units import format_duration, parse_duration, parse_feed, parse_length, parse_point


@pytest.mark.parametrize("text, seconds", [("4ms", 0.004), ("0.004s", 0.004), ("250us", 250e-6),
                                           ("250µs", 250e-6), (" 4 ms ", 0.004), ("1e-3s", 1e-3)])
def test_durations(text, seconds):
    assert parse_duration(text) == pytest.approx(seconds, rel=1e-15)


@pytest.mark.parametrize("text, message", [("4", "has no unit"), ("4min", "unknown unit 'min'"),
                                           ("0ms", "must be > 0"), ("fast", "cannot read"),
                                           ("-4ms", "must be > 0")])
def test_bad_durations(text, message):
    with pytest.raises(InputError, match=f"^period: .*{message}|^period must be > 0"):
        parse_duration(text)
    with pytest.raises(InputError, match=message):
        parse_duration(text)


def test_lengths_feeds_points():
    assert parse_length("3", "radius") == 3.0 == parse_length("3mm", "radius")
    assert parse_feed("1500") == 1500.0 == parse_feed("1500mm/min")
    assert parse_point("1, -2.5,3e1", "start") == (1.0, -2.5, 30.0)
    with pytest.raises(InputError, match="radius: lengths are in mm, got unit 'in'"):
        parse_length("3in", "radius")
    with pytest.raises(InputError, match="tolerance must be > 0 mm"):
        parse_length("0", "tolerance", allow_zero=False)
    with pytest.raises(InputError, match="feeds are in mm/min"):
        parse_feed("25mm/s")
    with pytest.raises(InputError, match="start: expected X,Y,Z in mm"):
        parse_point("1,2", "start")


def test_format_duration():
    assert format_duration(0.004) == "4 ms"
    assert format_duration(250e-6) == "250 us"
    assert format_duration(1.5) == "1.5 s"
