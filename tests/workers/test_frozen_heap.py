"""What a process starts a command with is kept out of the garbage collector's walks
where it lives to the end: in each worker (the parent's objects, copied by the fork), and
in the console program after its imports; never in a caller's own process."""

from __future__ import annotations

import gc

import pytest

import cadcnc
from cadcnc.cli.app import main as cli_main
from cadcnc.parallel.pool import START_ENV
from cadcnc.parallel.tasks import on_workers
from helpers.fixtures import FIXTURES


def _frozen(part, task, beat=None):
    """A task: how many objects the worker's collector leaves alone."""
    return gc.get_freeze_count()


@pytest.fixture(scope="module")
def part():
    return cadcnc.load_step(FIXTURES / "step_block.step")


@pytest.mark.parametrize("method", ["fork", "forkserver"])
def test_a_worker_freezes_what_it_started_with(part, monkeypatch, method):
    monkeypatch.setenv(START_ENV, method)
    frozen = on_workers(_frozen, [1, 2, 3], part, 2)
    assert min(frozen) > 1000   # the modules and the part at least


def test_the_callers_process_is_not_frozen(capsys):
    before = gc.get_freeze_count()
    assert cli_main(["faces", str(FIXTURES / "step_block.step")]) == 0
    assert gc.get_freeze_count() == before
