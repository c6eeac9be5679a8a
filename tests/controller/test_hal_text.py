"""The HAL file of the stream loop starts its stream, sampler and limit3 load together.

A ``sets cadcnc-start TRUE`` from halcmd can land while the servo thread runs; the
thread's first function latches it, so no function of that period sees the start
before the streamer does (the sampler would record, and limit3 load, a stale position
one period before the streamer's first row: a jump of the whole start offset)."""

from __future__ import annotations

import re
from dataclasses import dataclass

from cadcnc.controller.hal.loop import hal_text


@dataclass(frozen=True)
class _Machine:
    period: float = 0.004
    max_velocity: tuple = (100.0, 100.0, 50.0)
    max_acceleration: tuple = (1000.0, 1000.0, 500.0)


def _lines(text: str) -> list[str]:
    return [ln.split("#")[0].strip() for ln in text.splitlines() if ln.split("#")[0].strip()]


def test_the_start_is_latched_by_the_threads_first_function():
    lines = _lines(hal_text(_Machine(), 100))
    addf = [ln.split()[1] for ln in lines if ln.startswith("addf ")]
    assert addf[0] == "run-latch" and "streamer.0" in addf and "sampler.0" in addf
    nets = {ln.split()[1]: ln for ln in lines if ln.startswith("net ")}
    # the start signal reaches the latch only; the latched signal drives the three
    assert re.fullmatch(r"net cadcnc-start => run-latch\.in0", nets["cadcnc-start"])
    run = nets["cadcnc-run"]
    assert run.startswith("net cadcnc-run run-latch.out =>")
    assert {"streamer.0.enable", "sampler.0.enable", "load-pulse.in"} <= set(run.split()[4:])
    assert "setp run-latch.in1 TRUE" in lines
    assert not any(re.search(r"\bcadcnc-run\b", ln) for ln in lines
                   if ln.startswith("sets "))   # only the latch drives it
