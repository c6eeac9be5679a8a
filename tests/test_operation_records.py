"""The operation records and their one protocol: each finishing strategy its own record,
written to a program's JSON with the same keys as before (old files read back), and
every record run by the one planner registered for it."""

from __future__ import annotations

import json

import pytest

from cadcnc.core.errors import InputError
from cadcnc.core.job import (
    OPERATIONS,
    Job,
    PairPath,
    Pencil,
    Raster,
    SteepShallow,
    Tool,
    Waterline,
    finishing,
)
from cadcnc.ops.run import REGISTRY, cut_back_gap, run

FINISH_KEYS = ["operation", "faces", "stepover", "scallop", "angle", "pattern", "stepdown",
               "strategy", "threshold", "side", "overlap"]


def job(op) -> Job:
    return Job(Tool(3.0), 1500.0, 0.004, op)


@pytest.mark.parametrize("op", [Raster((5,), 1.0), Waterline((5,), stepdown=1.0),
                                SteepShallow((5,), scallop=0.1)])
def test_every_finishing_record_writes_the_formats_keys_and_reads_back(op):
    inputs = job(op).to_inputs()
    assert [k for k in inputs if k in FINISH_KEYS] == FINISH_KEYS
    assert inputs["operation"] == "finish" and inputs["strategy"] == op.strategy
    again = Job.from_inputs(json.loads(json.dumps(inputs)))
    assert again == job(op) and type(again.operation) is type(op)


def test_an_old_finish_job_reads_as_its_strategys_record():
    """A program written by the Finish record: every finishing key, those of other
    strategies at their defaults; one older still has no strategy (raster)."""
    old = {"radius": 3.0, "feed": 1500.0, "period": 0.004, "operation": "finish",
           "faces": [5], "stepover": None, "scallop": None, "angle": 0.0,
           "pattern": "zigzag", "stepdown": 2.0, "strategy": "waterline",
           "threshold": 45.0, "side": "conventional", "overlap": 0.0}
    assert Job.from_inputs(old).operation == Waterline((5,), stepdown=2.0,
                                                       side="conventional")
    older = {"radius": 3.0, "feed": 1500.0, "period": 0.004, "operation": "finish",
             "faces": [5], "stepover": 2.0}
    assert Job.from_inputs(older).operation == Raster((5,), 2.0)


@pytest.mark.parametrize("strategy, given, words", [
    ("raster", dict(stepover=1.0, stepdown=1.0), "stepdown is for waterline"),
    ("waterline", dict(stepdown=1.0, stepover=1.0), "stepover 1"),
    ("spiral", dict(stepover=1.0), "strategy"),
    ("raster", dict(stepover=1.0, spin=2), "no field spin"),
])
def test_the_strategy_factory_refuses_a_spacing_of_another_strategy(strategy, given, words):
    with pytest.raises(InputError, match=words):
        finishing(strategy, [5], **given)


def test_the_factory_leaves_out_fields_the_strategy_has_not():
    """The CLI gives every field (its defaults): a raster keeps its own."""
    op = finishing("raster", [5], stepover=1.0, angle=30.0, threshold=45.0, side="climb",
                   overlap=0.0, pattern="oneway")
    assert op == Raster((5,), 1.0, None, 30.0, "oneway")


def test_every_record_has_one_registered_operation():
    assert set(REGISTRY) == set(OPERATIONS)
    assert cut_back_gap(job(PairPath((4, 5)))) is None
    assert cut_back_gap(job(Pencil())) == 1e-3
    assert {cut_back_gap(job(op)) for op in (Raster((5,), 1.0), Waterline((5,), 1.0),
                                             SteepShallow((5,), scallop=0.1))} == {1e-6}


def test_run_refuses_what_is_not_a_job():
    with pytest.raises(InputError, match="job must be a cadcnc.Job"):
        run(None, Raster((5,), 1.0))


def test_each_record_describes_itself():
    assert Pencil((3, 1), "conventional").describe() == \
        "pencil, corners of faces 1 3, conventional"
    assert SteepShallow((1,), 1.0, 0.5, threshold=30, overlap=0.5).describe() == (
        "finish faces 1, steep-shallow, stepover 1 mm, stepdown 0.5 mm, threshold 30 deg, "
        "overlap 0.5 mm, climb")
