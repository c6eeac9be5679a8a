"""The batch's queue (issue 25): the largest parts go first, so that a long part does not
start last while the other workers sit idle."""

from __future__ import annotations

import os

import cadcnc
from helpers.fixtures import FIXTURES

# cadcnc.batch's engine and task import dask.distributed (about 1 s of CPU): imported in
# the tests, so that the xdist workers that do not run them do not pay for it at collection


def _part(name: str, operations: int = 1):
    from cadcnc.batch.task import BatchOperation, BatchPart

    path = str(FIXTURES / name)
    job = cadcnc.Job(cadcnc.Tool(3.0), 1500, 0.004, cadcnc.Pencil(), source=path)
    return BatchPart(path, tuple(BatchOperation("pencil", job, ("p.json",))
                                 for _ in range(operations)))


def test_larger_files_and_more_operations_queue_first():
    from cadcnc.batch.engine import queue_size
    from cadcnc.batch.task import BatchPart

    big, small = "abc_fold.step", "sphere_cylinder.step"
    assert os.path.getsize(FIXTURES / big) > os.path.getsize(FIXTURES / small)
    order = sorted([_part(small), _part(big)], key=lambda p: -queue_size(p))
    assert [os.path.basename(p.path) for p in order] == [big, small]
    assert queue_size(_part(small, 3)) == 3 * queue_size(_part(small))
    assert queue_size(BatchPart("/no/such.step", ())) == 0
