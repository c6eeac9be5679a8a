"""The Machine record and LinuxCNC INI reading: values, units, and named errors (exit 2)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cadcnc.controller.machine import Machine, read_machine_ini
from cadcnc.core.errors import InputError
from helpers.cli import cadcnc_cli

SAMPLE = Path("/usr/share/doc/linuxcnc/examples/sample-configs/by_machine/tormach/pcnc-770.ini")

GOOD = """
[EMCMOT]
SERVO_PERIOD = 1000000
[TRAJ]
LINEAR_UNITS = {units}
[AXIS_X]
MAX_VELOCITY = 2
MAX_ACCELERATION = 20
MAX_JERK = 400
[AXIS_Y]
MAX_VELOCITY = 3
MAX_ACCELERATION = 30
MAX_JERK = 500
[AXIS_Z]
MAX_VELOCITY = 1
MAX_ACCELERATION = 10
{z_jerk}
"""


def _ini(tmp_path, text: str) -> Path:
    path = tmp_path / "machine.ini"
    path.write_text(text)
    return path


def test_ini_in_inch_with_jerk_keys(tmp_path):
    m = read_machine_ini(_ini(tmp_path, GOOD.format(units="inch", z_jerk="MAX_JERK = 100")))
    assert m.period == pytest.approx(0.001)
    assert m.max_velocity == pytest.approx((50.8, 76.2, 25.4))
    assert m.max_acceleration == pytest.approx((508.0, 762.0, 254.0))
    assert m.max_jerk == pytest.approx((10160.0, 12700.0, 2540.0))


def test_missing_jerk_key_takes_the_option_else_is_named(tmp_path):
    path = _ini(tmp_path, GOOD.format(units="mm", z_jerk=""))
    assert read_machine_ini(path, jerk=5000.0).max_jerk == (400.0, 500.0, 5000.0)
    with pytest.raises(InputError, match=r"\[AXIS_Z\] MAX_JERK is missing.*--jerk"):
        read_machine_ini(path)


@pytest.mark.parametrize("edit, message", [
    (("SERVO_PERIOD = 1000000", "SERVO_PERIOD = fast"), r"\[EMCMOT\] SERVO_PERIOD = 'fast' is not a number"),
    (("SERVO_PERIOD = 1000000", ""), r"\[EMCMOT\] SERVO_PERIOD is missing"),
    (("SERVO_PERIOD = 1000000", "SERVO_PERIOD = 1"), r"SERVO_PERIOD = 1 ns: machine period"),
    (("LINEAR_UNITS = mm", "LINEAR_UNITS = furlong"), r"\[TRAJ\] LINEAR_UNITS = 'furlong'"),
    (("MAX_VELOCITY = 3", "MAX_VELOCITY = -3"), r"\[AXIS_Y\] MAX_VELOCITY = -3 must be"),
    (("MAX_ACCELERATION = 10\n", "\n"), r"\[AXIS_Z\] MAX_ACCELERATION is missing"),
    (("[AXIS_Y]", "[AXIS_V]"), r"section \[AXIS_Y\] is missing"),
    (("[EMCMOT]", "EMCMOT"), r"section \[EMCMOT\] is missing"),  # LinuxCNC: a stray line
])
def test_bad_ini_values_are_named(tmp_path, edit, message):
    text = GOOD.format(units="mm", z_jerk="MAX_JERK = 100").replace(*edit)
    path = _ini(tmp_path, text)
    with pytest.raises(InputError, match=message) as err:
        read_machine_ini(path)
    assert str(path) in str(err.value)


@pytest.mark.parametrize("field, value", [
    ("period", 0.0), ("period", float("nan")), ("period", 1.0),
    ("max_velocity", (1.0, 2.0)), ("max_acceleration", (1.0, 0.0, 1.0)),
    ("max_jerk", (1.0, float("inf"), 1.0)), ("max_jerk", "abc"),
])
def test_bad_limits_name_the_field(field, value):
    kwargs = dict(period=0.001, max_velocity=(1, 1, 1), max_acceleration=(1, 1, 1),
                  max_jerk=(1, 1, 1))
    kwargs[field] = value
    with pytest.raises(InputError, match=field):
        Machine(**kwargs)


@pytest.mark.skipif(not SAMPLE.exists(), reason="LinuxCNC's sample configurations absent")
def test_default_is_the_tormach_sample_config():
    m, d = read_machine_ini(SAMPLE, jerk=1.0), Machine.default()
    assert m.period == d.period
    assert m.max_velocity + m.max_acceleration == pytest.approx(
        d.max_velocity + d.max_acceleration)


def test_cli_bad_ini_and_limits_exit_2(tmp_path):
    bad = _ini(tmp_path, GOOD.format(units="mm", z_jerk=""))
    program = tmp_path / "p.json"
    program.write_text("{}")
    run = cadcnc_cli("stream", program, "--machine", bad, "-o", tmp_path / "s.npy", check=2)
    assert "MAX_JERK is missing" in run.stderr and "Traceback" not in run.stderr
    run = cadcnc_cli("stream", program, "--jerk", "-5", "-o", tmp_path / "s.npy", check=2)
    assert "jerk" in run.stderr
    run = cadcnc_cli("stream", program, "--machine", tmp_path / "none.ini", "-o",
                     tmp_path / "s.npy", check=2)
    assert "cannot read the machine INI" in run.stderr
    assert not (tmp_path / "s.npy").exists()
