"""A tool axis per setup (issue 23): ``--axis`` on the six sides of fixtures/six_pockets.step.

Each side's pocket corner is reachable only from that side (fixtures/build_setup_fixtures.py).
For each side the path of its floor / wall corner is computed with ``--axis``; its G-code is
read by LinuxCNC's rs274 and mapped back to part coordinates through the transform the
G-code's own comments state; every cut point then lies R from both faces, and every move
(cuts and links) keeps the ball and a shank along the axis clear of the part, both by
OCCT's BRepExtrema (not by cadcnc's guard). Bad axes exit 2.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from cadcnc.testing.rs274 import RS274
from cadcnc.testing.rs274 import moves as rs274_moves
from helpers.cli import cadcnc_cli
from helpers.six_pockets import (
    AXES,
    DIGITS,
    FACTS,
    GOUGE,
    SHANK,
    STEP,
    R,
    distance,
    face_distance,
    written_transform,
)


@pytest.fixture(scope="module")
def part():
    import cadcnc

    return cadcnc.load_step(STEP)


@pytest.mark.skipif(RS274 is None, reason="LinuxCNC rs274 not installed")
@pytest.mark.parametrize("side", list(AXES))
def test_axis_reaches_its_own_side(part, tmp_path, side):
    facts = FACTS["sides"][side]
    floor, wall = facts["floor"], facts["wall"]
    d, e = np.array(AXES[side], float), np.array(facts["across"])
    out = [tmp_path / f"p.{s}" for s in ("ngc", "json", "glb", "png")]
    # +Z without a work zero is the identity (part coordinates, as always): given one,
    # it is a setup like the others
    origin = ["--origin", "0,0,20"] if side == "+Z" else []
    run = cadcnc_cli("path", STEP, "--faces", floor, wall, "--radius", R, "--axis", side,
                     *origin, *[a for o in out for a in ("-o", o)], check=0)
    assert f"tool axis {side}" in run.stdout                  # the summary names the axis
    ngc = out[0].read_text()
    assert f"tool axis {side}" in ngc
    rot, zero = written_transform(ngc)
    assert np.allclose(rot @ d, [0, 0, 1])                    # the axis is the machine's +Z
    moves = rs274_moves(out[0])
    # mapped back through the written transform; the first move starts at the machine's
    # home, not a point of the program
    pts = np.array([p for _, p in moves]) @ rot + zero
    cut = [k for k, (kind, _) in enumerate(moves) if kind == "STRAIGHT_FEED"
           and abs(pts[k] @ d - (15 + R)) < DIGITS]
    assert len(cut) > 100
    for k in cut[::20]:
        p = pts[k]
        for n in (floor, wall):
            assert abs(face_distance(part, n, p) - R) <= DIGITS, (side, n, p)
        assert abs(p @ e - (-8 + R)) <= DIGITS                 # the closed form of the corner
    links = [k for k in range(2, len(moves)) if k - 1 not in cut or k not in cut]
    for a, b in [(pts[k - 1], pts[k]) for k in links] + [(pts[cut[0]], pts[cut[-1]])]:
        # every link move, and the cut (a straight corner) from end to end
        n = max(int(np.ceil(np.linalg.norm(b - a) / 1.0)), 1)
        for t in np.linspace(0.0, 1.0, n + 1):
            p = a + t * (b - a)
            assert distance(part.shape, p) >= R - GOUGE, (side, p)
            assert distance(part.shape, p, p + SHANK * d) >= R - GOUGE, (side, p)
    data = json.loads(out[1].read_text())                      # JSON: part coordinates
    assert data["setup"]["axis"] == list(d) and data["job"]["axis"] == list(d)
    cuts = np.vstack([s["points"] for s in data["segments"] if s["kind"] == "cut"])
    assert np.allclose(cuts @ d, 15 + R, atol=1e-9) and np.allclose(cuts @ e, -8 + R,
                                                                     atol=1e-9)
    from cadcnc.io.program_json import read_program

    back = read_program(out[1])   # read back into its work coordinates, as the G-code
    feeds = np.array([p for kind, p in moves if kind == "STRAIGHT_FEED"])
    assert np.abs(feeds[:, None, :] - back.cuts[0].points[None, ::40, :]).max(
        axis=2).min(axis=0).max() <= DIGITS
    import trimesh

    scene = trimesh.load(out[2])
    assert f"tool_axis {side}" in scene.geometry               # the picture shows the axis
    assert out[3].stat().st_size > 10_000


@pytest.mark.parametrize("side", ["+X", "-Y"])
def test_other_sides_do_not_reach(side):
    facts = FACTS["sides"][side]
    run = cadcnc_cli("path", STEP, "--faces", facts["floor"], facts["wall"], "--radius", R,
                     "--axis", "-Z", "-o", "unused.json")
    assert run.returncode == 3, run.stderr
    assert "tool axis -Z" in run.stderr and "shank" in run.stderr


@pytest.mark.parametrize("axis", ["0,0,0", "nan,0,1", "W", "1,2", "+Q"])
def test_bad_axis_exits_2(tmp_path, axis):
    run = cadcnc_cli("pencil", STEP, "--radius", R, "--axis", axis, "-o", tmp_path / "p.json")
    assert run.returncode == 2, (run.stdout, run.stderr)
    assert "axis" in run.stderr and "Traceback" not in run.stderr
    assert not (tmp_path / "p.json").exists()


def test_negative_axis_values_parse():
    from cadcnc.cli.app import _negative_points_joined, build_parser

    for argv in (["--axis", "-Z"], ["--axis", "-0.5,0,-1"], ["--axis=-X"]):
        args = build_parser().parse_args(_negative_points_joined(
            ["pencil", "p.step", "--radius", "2", "-o", "p.json", *argv]))
        assert args.axis == argv[-1].split("=")[-1]
    args = build_parser().parse_args(_negative_points_joined(
        ["pencil", "p.step", "--radius", "2", "-o", "p.json", "--setups", "-X,+Z"]))
    assert args.setups == "-X,+Z"


def test_job_axis_validated_and_recorded():
    import cadcnc
    from cadcnc.geometry.setup import rotation_for, table_angles

    tool = cadcnc.Tool(2.0)
    job = cadcnc.Job(tool, 1500, 0.004, cadcnc.Pencil(), axis=(0, 3, 4))
    assert job.axis == pytest.approx((0, 0.6, 0.8))
    assert cadcnc.Job.from_inputs(job.to_inputs()).axis == job.axis
    for bad in ((0, 0, 0), (float("nan"), 0, 1), "up", (1, 2), None):
        with pytest.raises(cadcnc.InputError, match="axis"):
            cadcnc.Job(tool, 1500, 0.004, cadcnc.Pencil(), axis=bad)
    rng = np.random.default_rng(23)
    for a in [*AXES.values(), *rng.normal(size=(20, 3))]:
        a = np.asarray(a, float) / np.linalg.norm(a)
        r = rotation_for(a)
        assert np.allclose(r @ r.T, np.eye(3), atol=1e-12) and np.linalg.det(r) > 0
        assert np.allclose(r @ a, [0, 0, 1], atol=1e-12)
        ang_a, ang_b = np.radians(table_angles(a))   # turning the part by A about X, then B about Y
        ca, sa, cb, sb = np.cos(ang_a), np.sin(ang_a), np.cos(ang_b), np.sin(ang_b)
        y_turned = np.array([a[0], ca * a[1] - sa * a[2], sa * a[1] + ca * a[2]])
        up = np.array([cb * y_turned[0] + sb * y_turned[2], y_turned[1],
                       -sb * y_turned[0] + cb * y_turned[2]])
        assert np.allclose(up, [0, 0, 1], atol=1e-12)


def test_turned_part_keeps_face_numbers(part):
    """The turned part's face n is the original's face n moved by the setup."""
    import cadcnc
    from cadcnc.geometry.setup import setup_in, setup_part

    job = cadcnc.Job(cadcnc.Tool(R), 1500, 0.004, cadcnc.Pencil(), axis=(1, 1, 1))
    turned = setup_part(part, job)
    s = setup_in(turned)
    assert "indexing table" in " ".join(s.describe())
    probes = np.random.default_rng(1).uniform(-30, 30, size=(4, 3))
    for n in (1, FACTS["sides"]["+X"]["floor"], len(part)):
        f0, f1 = part.face(n), turned.face(n)
        for q in probes:   # a rigid move keeps every distance to the same face
            assert abs(distance(f0.topods, q) - distance(f1.topods, s.to_setup(q))) < 1e-7
    lo, hi = turned.bounding_box()
    assert abs(hi[2]) < 1e-6   # work zero on the top seen along the axis


def test_setup_top_measured_once_per_axis(monkeypatch):
    """A setup's work zero (the top of the turned part) is measured once per axis: every
    gate of a setup's cut asks for the setup again (``resolve_part``) and gets the same
    turned part and setup without another optimal box; another axis is measured anew."""
    import cadcnc
    from cadcnc.geometry import setup as setup_module
    from cadcnc.verification.surface_checks import resolve_part

    fresh = cadcnc.load_step(STEP)   # nothing measured on it yet
    boxes = []
    real = setup_module.optimal_box

    def counted(*args, **kwargs):
        boxes.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(setup_module, "optimal_box", counted)
    job = cadcnc.Job(cadcnc.Tool(R), 1500, 0.004, cadcnc.Pencil(), axis=(1, 0, 0))
    turned = setup_module.setup_part(fresh, job)
    first = setup_module.setup_in(turned)
    assert len(boxes) == 1

    class Toolpath:   # what resolve_part reads of a cut's path
        pass

    path = Toolpath()
    path.job = job
    for _ in range(3):
        assert resolve_part(path, turned) is turned
    again = setup_module.setup_of(fresh, job.axis)
    assert np.array_equal(again.origin, first.origin)
    assert np.array_equal(again.rotation, first.rotation)
    assert len(boxes) == 1
    again.origin[0] += 1.0   # a caller's change to its setup leaves the kept top alone
    assert np.array_equal(setup_module.setup_of(fresh, job.axis).origin, first.origin)
    other = setup_module.setup_of(fresh, (0, -1, 0))
    assert len(boxes) == 2 and not np.allclose(other.origin, first.origin)


def test_a_program_of_another_axis_streams_on_its_turned_part(part, tmp_path):
    """``cadcnc stream`` on a program computed with ``--axis -Z``: the part is turned into
    the program's recorded setup before the stream is checked and gated (it had been read
    in part coordinates, and the program refused as "computed on another part"). The
    streamed positions, in work coordinates, mapped back to part coordinates through the
    recorded rotation and work zero, lie R from both faces along the cut (OCCT)."""
    facts = FACTS["sides"]["-Z"]
    floor, wall = facts["floor"], facts["wall"]
    program, npy = tmp_path / "p.json", tmp_path / "s.npy"
    cadcnc_cli("path", STEP, "--faces", floor, wall, "--radius", R, "--axis", "-Z",
               "-o", program)
    run = cadcnc_cli("stream", program, "--feed", "3000", "-o", npy, check=0)
    assert "wrote" in run.stdout
    setup = json.loads(program.read_text())["setup"]
    rot, zero = np.array(setup["rotation"]), np.array(setup["origin"])
    pts = np.load(npy) @ rot + zero                      # part coordinates
    d = np.array(AXES["-Z"], float)
    on_cut = pts[np.abs(pts @ d - (15 + R)) < DIGITS]
    assert len(on_cut) > 100
    for p in on_cut[::50]:
        for n in (floor, wall):
            assert abs(face_distance(part, n, p) - R) <= DIGITS, (n, p)
