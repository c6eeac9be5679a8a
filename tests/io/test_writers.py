"""JSON and CSV writers: exact round trips, non-finite numbers, atomic writes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cadcnc.core.errors import InputError, OutputError
from cadcnc.io import (
    CSV_COLUMNS,
    atomic_write,
    check_output,
    read_csv,
    read_json,
    toolpath_from_dict,
    toolpath_to_dict,
    write_csv,
    write_json,
)
from cadcnc.io.program_gcode import write_ngc
from helpers.fixtures import fixture_path
from helpers.programs import assert_same_path


@pytest.fixture(scope="module")
def saddle():
    return fixture_path("crossing_cylinders", 1, 2)


def test_json_round_trip_is_exact(saddle, tmp_path):
    out = tmp_path / "p.json"
    write_json(saddle, out)
    back = read_json(out)
    assert_same_path(saddle, back)
    assert back.length == saddle.length and back.duration == saddle.duration
    assert back.worst_predicted_mm == saddle.worst_predicted_mm
    data = json.loads(out.read_text())
    assert data["format"] == "cadcnc-toolpath" and data["summary"]["points"] == len(saddle)
    assert data["inputs"]["period"] == 0.004 and data["inputs"]["feed"] == 1500.0


def test_json_non_finite_numbers_are_legal_json(saddle, tmp_path):
    d = toolpath_to_dict(saddle)
    d["bounds"][0]["eq16"][3] = "Infinity"
    d["bounds"][1]["eq11"][0] = "NaN"
    text = json.dumps(d, allow_nan=False)  # the writer's own output must pass this too
    back = toolpath_from_dict(json.loads(text))
    assert np.isposinf(back.bounds[0].eq16[3]) and np.isnan(back.bounds[1].eq11[0])
    again = toolpath_to_dict(back)
    assert again["bounds"][0]["eq16"][3] == "Infinity"
    json.dumps(toolpath_to_dict(saddle), allow_nan=False)


@pytest.mark.parametrize("bad, message", [
    ({"format": "other"}, "not a cadcnc toolpath"),
    ({"format": "cadcnc-toolpath", "version": 99}, "version 99"),
    ({"format": "cadcnc-toolpath", "version": 1, "points": []}, "incomplete"),
])
def test_json_errors(bad, message):
    with pytest.raises(InputError, match=message):
        toolpath_from_dict(bad)


def test_read_json_names_the_file(tmp_path):
    (tmp_path / "x.json").write_text("{not json")
    with pytest.raises(InputError, match="x.json: not a toolpath JSON"):
        read_json(tmp_path / "x.json")
    with pytest.raises(InputError, match="no such file"):
        read_json(tmp_path / "missing.json")


def test_csv_one_row_per_cycle(saddle, tmp_path):
    out = tmp_path / "p.csv"
    write_csv(saddle, out)
    assert out.read_text().splitlines()[0] == ",".join(CSV_COLUMNS)
    cols = read_csv(out)
    assert len(cols["x"]) == len(saddle)
    np.testing.assert_array_equal(np.column_stack([cols["x"], cols["y"], cols["z"]]),
                                  saddle.points)
    np.testing.assert_array_equal(cols["cycle"], np.arange(len(saddle)))
    np.testing.assert_allclose(cols["t_s"], np.arange(len(saddle)) * 0.004)
    np.testing.assert_array_equal(cols["step"], saddle.steps)
    np.testing.assert_array_equal(cols["u2"], saddle.uv[:, 1, 0])
    np.testing.assert_array_equal(cols["bound1"], saddle.bounds[0].eq16)


def test_atomic_write_leaves_nothing_on_failure(tmp_path):
    target = tmp_path / "keep.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_write(target) as fh:
            fh.write("half")
            raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt"]
    with atomic_write(tmp_path / "new.txt") as fh:
        fh.write("whole")
    assert (tmp_path / "new.txt").read_text() == "whole"


def test_failed_gcode_write_leaves_no_file(saddle, tmp_path):
    out = tmp_path / "p.ngc"
    with pytest.raises(InputError, match="safe Z"):
        write_ngc([saddle], out, safe_z=0.0)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("name, message", [
    ("p.txt", "unknown output format '.txt'"),
    ("p", "unknown output format '\\(no suffix\\)'"),
    ("missing/p.json", "missing does not exist"),
])
def test_check_output(tmp_path, name, message):
    with pytest.raises(OutputError, match=message):
        check_output(tmp_path / name)
