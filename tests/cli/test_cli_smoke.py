"""The console script as users start it: a few subprocess runs (each pays ~2 s of imports)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from helpers.fixtures import FIXTURES


def cadcnc(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "cadcnc.cli", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


def test_help_without_importing_occt():
    run = cadcnc("--help")
    assert run.returncode == 0 and "verify" in run.stdout
    probe = subprocess.run([sys.executable, "-c", "import sys; from cadcnc.cli.app import "
                            "build_parser; build_parser(); print('OCP' in sys.modules)"],
                           capture_output=True, text=True, timeout=60)
    assert probe.stdout.strip() == "False", probe.stderr


def test_path_end_to_end(tmp_path):
    out = tmp_path / "p.json"
    run = cadcnc("path", FIXTURES / "bspline_boss.step", "--faces", "4", "5", "--radius", "3",
                 "--feed", "1500", "--period", "4ms", "-o", out)
    assert run.returncode == 0, run.stderr
    assert ", 697 points," in run.stdout and "result     complete" in run.stdout and out.read_bytes().startswith(b"{")


def test_error_is_one_line_with_exit_code(tmp_path):
    run = cadcnc("faces", "nope.step", cwd=tmp_path)
    assert run.returncode == 2
    assert run.stderr == "cadcnc: error: nope.step: no such file\n"


def test_faces_loads_neither_numba_nor_the_interpolation_core():
    """Listing a part's faces reads the part only (issue 20: it took 2.7 s and 420 MB)."""
    code = ("import sys; from cadcnc.cli import main; "
            f"main(['faces', {str(FIXTURES / 'pocket.step')!r}]); "
            "print('numba' in sys.modules, any(m.startswith('cadcnc.interp') for m in "
            "sys.modules))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines()[-1] == "False False"


@pytest.mark.slow   # a fresh process runs a whole finish command (~2.5 s)
def test_finish_loads_neither_the_other_operations_nor_the_feed_planner(tmp_path):
    """An operation imports what it runs (issue 37, item 5): ``finish`` neither the pencil
    and path programs (``pencil --setups`` included) nor the stream's planner, which only
    ``--stream`` needs; the program is still written."""
    out = tmp_path / "p.ngc"
    code = ("import sys; from cadcnc.cli import main; "
            f"code = main(['finish', {str(FIXTURES / 'finish_slab.step')!r}, '--faces', '5', "
            f"'--radius', '3', '--stepover', '8', '-q', '-o', {str(out)!r}]); "
            "print(code, sorted(m for m in sys.modules if m.startswith(("
            "'cadcnc.ops.pencil', 'cadcnc.ops.path.pair_program', 'cadcnc.controller.feed_plan', "
            "'cadcnc.controller.run_plan', "
            "'cadcnc.controller.stream', 'cadcnc.pipeline.streaming', "
            "'cadcnc.pipeline.setup_programs'))))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines()[-1] == "0 []" and "M2" in out.read_text()


def test_a_long_stage_reports_at_least_every_five_seconds():
    """The gate's stages (and any caller of stage_progress) are never silent longer than
    the heartbeat, by a fake clock: one line when a stage starts, then one per 5 s."""
    from types import SimpleNamespace

    from cadcnc.cli import feedback

    now, lines, times = [0.0], [], []
    feedback_say = feedback.say_error
    feedback.say_error = lambda text: (lines.append(text), times.append(now[0]))
    try:
        report = feedback.stage_progress(SimpleNamespace(quiet=False), "gate",
                                         clock=lambda: now[0])
        for k in range(100):          # 100 steps of 0.7 s of one stage
            now[0] += 0.7
            report(k, 100, "moves")
    finally:
        feedback.say_error = feedback_say
    assert lines[0] == "cadcnc: gate: moves ..." and "/100" in lines[-1]
    gaps = [b - a for a, b in zip(times, times[1:] + [now[0]])]
    assert max(gaps) <= 5.0 + 0.7 + 1e-9 and len(lines) >= 12   # 5 s, to the next call
