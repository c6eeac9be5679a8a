"""The documentation's Python examples run as written (so the docs cannot rot)."""

from __future__ import annotations

import os
import re

from helpers.fixtures import ROOT
from helpers.programs import pencil_run


def test_api_examples_run(monkeypatch):
    text = (ROOT / "docs" / "api.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    monkeypatch.chdir(ROOT)
    sent = []
    namespace = {"send_to_axes": sent.append}
    for block in blocks:
        exec(compile(block, "docs/api.md", "exec"), namespace)
    assert namespace["path"].stop_reason == "closed"
    assert namespace["job"].step == 0.1 and namespace["corner"].job.operation.faces == (4, 5)
    assert namespace["program"].complete and namespace["program"].cuts
    assert namespace["stepper"].stop_reason == "closed"
    assert len(sent) == namespace["stepper"].cycles
    assert os.path.exists(ROOT / "fixtures" / "bspline_boss.step")


def test_finish_example_runs_as_script_and_under_cq_editor(capsys):
    """docs/examples/finish_example.py: a Workplane and a selection of its faces in, a
    complete program out, shown with show_object or summarised."""
    import runpy

    example = str(ROOT / "docs" / "examples" / "finish_example.py")
    shown = {}
    ns = runpy.run_path(example, init_globals={
        "show_object": lambda obj, name="", options=None: shown.__setitem__(name, obj)})
    prog = ns["program"]
    assert set(shown) == {"part", "cuts", "links"} and prog.complete and prog.cuts
    assert prog.job.operation.faces and len(prog.job.operation.faces) == 3  # top, 2 rounds
    runpy.run_path(example, run_name="__main__")
    assert "finish R 2:" in capsys.readouterr().out


def test_show_program_shows_a_part_as_a_cadquery_shape():
    """cadcnc.show_program given a cadcnc Part hands show_object a CadQuery Shape (what
    CQ-editor can draw), then the cuts and the links as compounds."""
    import cadquery as cq

    import cadcnc
    from helpers.fixtures import load_fixture

    part = load_fixture("bspline_boss")
    program = pencil_run(part, radius=3.0)
    shown = {}
    cadcnc.show_program(lambda obj, name="", options=None: shown.__setitem__(name, obj),
                        program, part)
    assert set(shown) == {"part", "cuts", "links"}
    assert isinstance(shown["part"], cq.Shape) and shown["part"].isValid()
    assert all(isinstance(shown[k], cq.Compound) for k in ("cuts", "links"))


def test_the_top_level_names_are_the_ones_docs_api_lists():
    """``cadcnc``'s public names (about 15) are those of docs/api.md's table, each loads."""
    import cadcnc

    table = (ROOT / "docs" / "api.md").read_text().split("## The names")[1].split("\n## ")[0]
    listed = {name for row in table.splitlines() if row.startswith("| `")
              for name in re.findall(r"`(\w+)`", row.split("|")[1])}
    assert listed == set(cadcnc.__all__) and len(listed) <= 20
    assert all(getattr(cadcnc, name) is not None for name in listed)
