"""The simulation against a part (fixtures/pocket.step: floor z = 15 inside x -30..30,
y -20..20): material left, a program edited to cut 0.05 mm into the floor reported at its
place and depth, a rapid through stock, G-code through rs274, the command's exit codes."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import EXIT_GOUGE, EXIT_INPUT, EXIT_OK, InputError
from cadcnc.simulation.simulator import simulate
from cadcnc.simulation.tool_moves import Run
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

POCKET = FIXTURES / "pocket.step"
R, RES, FLOOR = 3.0, 0.2, 15.0
UP = np.array([0.0, 0.0, 1.0])


@pytest.fixture(scope="module")
def part():
    return cadcnc.load_step(POCKET)


def run(points, rapid=None, shank=None):
    pts = np.asarray(points, float)
    flags = np.zeros(len(pts) - 1, bool) if rapid is None else np.asarray(rapid, bool)
    return Run(pts, flags, R, UP, 40.0, shank)


@pytest.fixture(scope="module")
def clean(part):
    """One pass along the floor, the ball touching it: no gouge."""
    return simulate(part, [run([(-20, 0, FLOOR + R), (20, 0, FLOOR + R)])],
                    resolution=RES, jobs=1)


@pytest.fixture(scope="module")
def gouged(part):
    """The same pass with its middle point 0.05 mm lower."""
    return simulate(part, [run([(-20, 0, FLOOR + R), (0, 0, FLOOR + R - 0.05),
                                (20, 0, FLOOR + R)])], resolution=RES, jobs=1)


def test_a_pass_touching_the_floor_leaves_nothing_under_it_and_takes_nothing(clean):
    d = clean.to_dict()
    assert d["gouges"] == [] and d["collisions"] == [] and clean.exit_code == EXIT_OK
    s = clean.samples
    under = (s.face == 17) & (np.abs(s.point[:, 1]) < 0.5) & (np.abs(s.point[:, 0]) < 15)
    assert under.sum() > 50
    # the floor under the pass: left R - sqrt(R^2 - y^2) (rays along Z are exact)
    y = s.point[under, 1]
    assert np.abs(s.left[under] - (R - np.sqrt(R * R - y * y))).max() < 1e-6
    floor = next(f for f in d["faces"] if f["face"] == 17)
    assert floor["max_left_mm"] == pytest.approx(15.0 + 1.0, abs=1e-6)   # uncut: to the top
    assert set(floor) >= {"face", "max_left_mm", "p99_left_mm", "mean_left_mm",
                          "area_over_mm2"}
    assert d["resolution_mm"] == RES and d["stock"]["kind"] == "box"


def test_a_cut_005_into_the_floor_is_reported_at_its_place_and_depth(gouged):
    assert gouged.exit_code == EXIT_GOUGE
    (g,) = gouged.to_dict()["gouges"]
    assert g["face"] == 17
    assert abs(g["depth_mm"] - 0.05) <= RES ** 2 / (2 * R) + 1e-6   # within the rays' spacing
    assert np.linalg.norm(np.subtract(g["at"], (0, 0, FLOOR - 0.05))) <= RES
    floor = next(f for f in gouged.to_dict()["faces"] if f["face"] == 17)
    assert floor["gouges"] >= 1 and floor["deepest_gouge_mm"] == g["depth_mm"]


def test_a_rapid_through_the_block_is_a_collision(part):
    rep = simulate(part, [run([(-60, 0, 40), (-60, 0, 25), (60, 0, 25)],
                              rapid=[True, True])], resolution=1.0, jobs=1)
    (c,) = rep.to_dict()["collisions"]
    assert c["move"] == 2 and c["program"] == 1 and rep.exit_code == EXIT_GOUGE
    assert c["at"][0] == pytest.approx(-51, abs=1.0)   # met at the stock's side, x = -51


def test_work_over_the_limit_is_refused_with_a_resolution_that_fits(part):
    with pytest.raises(InputError, match=r"needs about .* GB.*give --resolution"):
        simulate(part, [run([(-20, 0, 18), (20, 0, 18)])], resolution=0.001)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("rs274") is None, reason="LinuxCNC rs274 not installed")
def test_gcode_through_rs274_and_the_command_exit_codes(tmp_path):
    """The gouged pass as G-code (tool tip programmed): exit 5, the report's fields."""
    ngc = tmp_path / "g.ngc"
    ngc.write_text("G21 G90 G17\nG0 X-20 Y0 Z25\nG1 Z15 F500\nG1 X0 Z14.95\nG1 X20 Z15\n"
                   "G0 Z25\nM2\n")
    out = tmp_path / "r.json"
    cadcnc_cli("simulate", POCKET, ngc, "--radius", R, "--tool-tip", "--resolution", 0.25,
               "-o", out, "-o", tmp_path / "r.png", check=EXIT_GOUGE)
    d = json.loads(out.read_text())
    assert {"faces", "gouges", "collisions", "resolution_mm", "stock"} <= set(d)
    assert d["gouges"][0]["face"] == 17 and d["exit_code"] == EXIT_GOUGE
    assert abs(d["gouges"][0]["depth_mm"] - 0.05) < 0.25 ** 2 / (2 * R)
    assert (tmp_path / "r.png").stat().st_size > 10_000
    run = cadcnc_cli("simulate", POCKET, ngc, "-o", tmp_path / "x.json", check=EXIT_INPUT)
    assert "--radius" in run.stderr and not (tmp_path / "x.json").exists()
    cadcnc_cli("simulate", POCKET, ngc, "--radius", R, "--stock", "offset", "x", "-o",
               tmp_path / "x.json", check=EXIT_INPUT)


def test_a_step_stock_and_an_offset_stock(part):
    """The part itself as the stock holds the part's volume (within 0.1 %); the part offset
    by 0.5 mm (OCCT's offset) holds more, within 20 %."""
    far = [run([(-80, 0, 40), (-70, 0, 40)])]
    same = simulate(part, far, stock=str(POCKET), resolution=0.5, jobs=1)
    volume = json.loads((FIXTURES / "fixtures.json").read_text())["pocket"]["volume"]
    assert same.stock.volume() == pytest.approx(volume, rel=1e-3)
    assert same.to_dict()["stock"]["kind"] == "step" and same.to_dict()["gouges"] == []
    grown = simulate(part, far, stock=0.5, resolution=0.5, jobs=1)
    assert grown.to_dict()["stock"] == {**grown.to_dict()["stock"], "kind": "offset",
                                        "offset_mm": 0.5}
    assert volume < grown.stock.volume() < volume * 1.2
