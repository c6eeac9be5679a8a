"""The exit-code rules that combine several results (docs/reliability.md): one part's
programs exit with the worst; a batch of parts with their one code, else partial."""

from __future__ import annotations

from cadcnc.core.errors import (
    EXIT_GOUGE,
    EXIT_INPUT,
    EXIT_NOTHING,
    EXIT_OK,
    EXIT_PARTIAL,
)
from cadcnc.pipeline.exit_policy import across_parts, worst


def test_a_batch_exits_0_only_when_every_part_did():
    assert across_parts([]) == EXIT_OK
    assert across_parts([EXIT_OK] * 3) == EXIT_OK


def test_a_batch_whose_parts_failed_one_way_exits_that_way():
    assert across_parts([EXIT_GOUGE, EXIT_GOUGE]) == EXIT_GOUGE
    assert across_parts([EXIT_INPUT]) == EXIT_INPUT


def test_a_mixed_batch_is_partial():
    assert across_parts([EXIT_OK, EXIT_GOUGE]) == EXIT_PARTIAL
    assert across_parts([EXIT_NOTHING, EXIT_INPUT]) == EXIT_PARTIAL


def test_one_parts_programs_exit_with_the_worst():
    assert worst([EXIT_OK, EXIT_NOTHING, EXIT_GOUGE]) == EXIT_GOUGE
    assert worst([EXIT_OK, EXIT_INPUT, EXIT_GOUGE]) == EXIT_INPUT
    assert worst([]) == EXIT_OK
