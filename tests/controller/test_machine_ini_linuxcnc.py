"""Machine INI files read as LinuxCNC reads them (issue 36, finding 1): cadcnc's values
against ``inivar``'s (LinuxCNC's own reader) on awkward files; ``#INCLUDE`` expanded by
the ``linuxcnc`` launcher's own ``handle_includes``. Without LinuxCNC installed the
comparison is skipped and cadcnc's side still checked."""

from __future__ import annotations

import shutil
import subprocess
import warnings
from pathlib import Path

import pytest

from cadcnc.controller.ini_file import leading_number
from cadcnc.controller.machine import IniWarning, read_machine_ini
from cadcnc.core.errors import InputError
from helpers.cli import cadcnc_cli
from helpers.fixtures import FIXTURES

# 4 mm of the block's straight corner (faces 3 and 8), as in test_controller_cli.py
SHORT = ["--faces", "3", "8", "--radius", "3", "--start", "19.0919,-23.3345,11",
         "--end", "16.2635,-20.5061,11"]
HEAD = "[EMCMOT]\nSERVO_PERIOD = 1000000\n[TRAJ]\nLINEAR_UNITS = {units}\n"
AXIS = "[AXIS_{a}]\nMAX_VELOCITY = {v}\nMAX_ACCELERATION = {acc}\nMAX_JERK = {j}\n"


def _axes(z: str = "") -> str:
    text = AXIS.format(a="X", v=2, acc=20, j=400) + AXIS.format(a="Y", v=3, acc=30, j=500)
    return text + (z or AXIS.format(a="Z", v=1, acc=10, j=100))


AWKWARD = {
    "repeated key": HEAD.format(units="mm") + _axes(
        "[AXIS_Z]\nMAX_VELOCITY = 30\nMAX_VELOCITY = 3000\nMAX_ACCELERATION = 300\n"
        "MAX_JERK = 9000\n"),
    "repeated section": HEAD.format(units="mm") + _axes(
        "[AXIS_Z]\nMAX_VELOCITY = 30\nMAX_ACCELERATION = 300\nMAX_JERK = 9000\n"
        "[AXIS_Z]\nMAX_ACCELERATION = 30000\n"),
    "CRLF": (HEAD.format(units="mm") + _axes()).replace("\n", "\r\n"),
    "comments after values": HEAD.format(units="mm") + _axes(
        "[AXIS_Z]\nMAX_VELOCITY = 30   # mm/s\nMAX_ACCELERATION = 300 ; fast\n"
        "  MAX_JERK\t=\t9000  \n"),
    "inch": HEAD.format(units="inch") + _axes(),
    "prefixed key, blanks": HEAD.format(units="mm") + _axes(
        "[AXIS_Z] ; the spindle axis\nMAX_VELOCITY_OLD = 99\n; MAX_VELOCITY = 7\n"
        "MAX_VELOCITY = 30\nMAX_ACCELERATION = 300\nMAX_JERK = 9000\n"),
}
KEYS = [("EMCMOT", "SERVO_PERIOD"), ("TRAJ", "LINEAR_UNITS")] + [
    (f"AXIS_{a}", k) for a in "XYZ" for k in ("MAX_VELOCITY", "MAX_ACCELERATION", "MAX_JERK")]


def _inivar(path: Path, section: str, key: str) -> str | None:
    out = subprocess.run(["inivar", "-ini", str(path), "-sec", section, "-var", key],
                         capture_output=True, text=True, timeout=30)
    return out.stdout.strip() if out.returncode == 0 else None


def _launcher_expanded(path: Path) -> Path:
    """The file LinuxCNC's launcher reads: its own handle_includes (bash) run on it."""
    script = ('source <(sed -n "/^function handle_includes/,/^}/p" "$(command -v linuxcnc)"); '
              'GREP=grep; handle_includes "$1"')
    out = subprocess.run(["bash", "-c", script, "-", str(path)], capture_output=True,
                         text=True, timeout=30, check=True)
    return Path(out.stdout.strip().splitlines()[-1])


def _read(path: Path):
    said = []
    return read_machine_ini(path, warn=said.append), said


def _check_against_inivar(path: Path, machine, read_from: Path) -> None:
    if shutil.which("inivar") is None:
        return
    scale = 25.4 if _inivar(read_from, "TRAJ", "LINEAR_UNITS") == "inch" else 1.0
    for section, key in KEYS[2:]:
        axis = "XYZ".index(section[-1])
        raw = _inivar(read_from, section, key)
        mine = getattr(machine, "max_" + key[4:].lower())[axis]
        assert raw is not None, (section, key)
        assert mine == pytest.approx(scale * leading_number(raw)[0], rel=1e-15), (section, key)
    period = leading_number(_inivar(read_from, "EMCMOT", "SERVO_PERIOD"))[0]
    assert machine.period == pytest.approx(period * 1e-9, rel=1e-15)


@pytest.mark.parametrize("name", list(AWKWARD))
def test_values_are_linuxcncs(tmp_path, name):
    path = tmp_path / "machine.ini"
    path.write_bytes(AWKWARD[name].encode())
    machine, said = _read(path)
    _check_against_inivar(path, machine, path)
    if name in ("repeated key", "repeated section", "comments after values",
                "prefixed key, blanks"):
        assert machine.max_velocity[2] == 30 and machine.max_acceleration[2] == 300
    if name == "inch":
        assert machine.max_velocity == pytest.approx((50.8, 76.2, 25.4))


def test_a_repeated_key_warns_naming_both_lines(tmp_path):
    """The finding: cadcnc took the last MAX_VELOCITY (3000), LinuxCNC the first (30)."""
    path = tmp_path / "machine.ini"
    path.write_text(AWKWARD["repeated key"])
    machine, said = _read(path)
    assert machine.max_velocity[2] == 30
    assert any(f"{path}:15:" in s and f"{path}:14" in s and "MAX_VELOCITY = 3000" in s
               for s in said), said


def test_a_repeated_section_is_ignored_as_by_linuxcnc(tmp_path):
    path = tmp_path / "machine.ini"
    path.write_text(AWKWARD["repeated section"])
    machine, said = _read(path)
    assert machine.max_acceleration[2] == 300
    assert any("repeated section [AXIS_Z]" in s and f"{path}:18" in s for s in said), said


def test_include_is_expanded_as_the_launcher_does(tmp_path):
    (tmp_path / "axes.inc").write_text(_axes())
    path = tmp_path / "machine.ini"
    path.write_text(HEAD.format(units="inch") + "#INCLUDE axes.inc\n")
    machine, _ = _read(path)
    assert machine.max_velocity == pytest.approx((50.8, 76.2, 25.4))
    if shutil.which("linuxcnc") and shutil.which("inivar"):
        _check_against_inivar(path, machine, _launcher_expanded(path))
    path.write_text(HEAD.format(units="inch") + "#INCLUDE missing.inc\n")
    with pytest.raises(InputError, match=r"machine.ini:5: #INCLUDE missing.inc: cannot read"):
        _read(path)


def test_a_lone_carriage_return_is_refused(tmp_path):
    path = tmp_path / "machine.ini"
    path.write_bytes((HEAD.format(units="mm") + _axes()).replace(
        "MAX_JERK = 400", "MAX_JERK = 4\r00").encode())
    with pytest.raises(InputError, match=r"machine.ini:\d+: a carriage return"):
        _read(path)


def test_warnings_default_to_python_warnings(tmp_path):
    path = tmp_path / "machine.ini"
    path.write_text(AWKWARD["repeated key"])
    with pytest.warns(IniWarning, match="LinuxCNC uses the first"):
        read_machine_ini(path)


def test_huge_limits_are_input_errors_without_overflow(tmp_path):
    """INI velocity 1e308: exit 2 naming the key, no numpy overflow warning."""
    path = tmp_path / "machine.ini"
    path.write_text(HEAD.format(units="mm") + _axes().replace("MAX_VELOCITY = 1",
                                                              "MAX_VELOCITY = 1e308"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=r"\[AXIS_Z\] MAX_VELOCITY = 1e\+308 units/s is over"):
            _read(path)


def test_cli_prints_the_warning_and_streams_linuxcncs_value(tmp_path):
    """The finding's run: the stream keeps Z within LinuxCNC's 30 mm/s (exit 0)."""
    import numpy as np

    program = tmp_path / "p.json"
    cadcnc_cli("path", FIXTURES / "step_block.step", *SHORT, "-o", program, check=0)
    path = tmp_path / "machine.ini"
    path.write_text(AWKWARD["repeated key"])
    run = cadcnc_cli("stream", program, "--machine", path, "-o", tmp_path / "s.npy")
    assert run.returncode == 0, run.stderr
    assert "cadcnc: warning:" in run.stderr and "MAX_VELOCITY = 3000" in run.stderr
    assert "Traceback" not in run.stderr
    vz = np.abs(np.diff(np.load(tmp_path / "s.npy")[:, 2])).max() / 1e-3
    assert vz <= 30 * (1 + 1e-6)
