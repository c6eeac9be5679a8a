"""Every fixture program is the same bytes as recorded (issue 38: a refactoring changes no
program, G-code or stream).

Each case of :mod:`benchmarks.identity.cases` runs the ``cadcnc`` command line as a user
would (a fresh process per command, ``--jobs 1``) on a copy of its fixture, and every file
it writes is compared by SHA-256 with ``tests/data/program_digests.json``, as are the exit
codes. Both ``FAST`` (about 40 s of CPU) and ``SLOW`` run in the slow tier; the checks that the
comparison can fail run in the fast one.
After an intended change, re-record the cases it changes and say why in the commit:

    python -m benchmarks identity --only CASE... --record tests/data/program_digests.json

The last tests show that the comparison fails on a changed, missing or extra file.
"""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from pathlib import Path

import pytest

from benchmarks.identity import __main__ as identity
from benchmarks.identity.cases import FAST, SLOW
from benchmarks.identity.harness import NORMALISERS, compare, digest_outputs, read_digests, run_case
from helpers.fixtures import FIXTURES, ROOT

DIGESTS = ROOT / "tests" / "data" / "program_digests.json"
RECORDED = read_digests(DIGESTS)["cases"]
RERECORD = ("if the change is intended, re-record (and say why in the commit): python -m "
            "benchmarks identity --only {name} --record tests/data/program_digests.json")


def groups(cases, n: int) -> list[list]:
    """``cases`` in ``n`` groups of about equal recorded CPU time (longest first onto the
    lightest group), each run by one class: xdist's loadscope gives a class to one worker."""
    out = [[] for _ in range(n)]
    load = [0.0] * n
    for case in sorted(cases, key=lambda c: -RECORDED.get(c.name, {}).get("cpu_s", 0.0)):
        k = load.index(min(load))
        out[k].append(case)
        load[k] += RECORDED.get(case.name, {}).get("cpu_s", 0.0)
    return out


def check(case) -> None:
    assert case.name in RECORDED, f"{case.name}: not recorded; " + RERECORD.format(
        name=case.name)
    result = run_case(case, FIXTURES)
    diffs = compare(RECORDED[case.name], result)
    assert not diffs, ("programs changed:\n  " + "\n  ".join(diffs) + "\n"
                       + "".join(e for e in result.stderr if e) + RERECORD.format(
                           name=case.name))


FAST_GROUPS, SLOW_GROUPS = groups(FAST, 2), groups(SLOW, 4)


def name(case) -> str:
    return case.name


@pytest.mark.slow  # 40 s of CPU with the other FAST cases: the fast tier keeps 90 s
class TestFastA:
    @pytest.mark.parametrize("case", FAST_GROUPS[0], ids=name)
    def test_identical(self, case):
        check(case)


@pytest.mark.slow
class TestFastB:
    @pytest.mark.parametrize("case", FAST_GROUPS[1], ids=name)
    def test_identical(self, case):
        check(case)


@pytest.mark.slow
class TestSlowA:
    @pytest.mark.parametrize("case", SLOW_GROUPS[0], ids=name)
    def test_identical(self, case):
        check(case)


@pytest.mark.slow
class TestSlowB:
    @pytest.mark.parametrize("case", SLOW_GROUPS[1], ids=name)
    def test_identical(self, case):
        check(case)


@pytest.mark.slow
class TestSlowC:
    @pytest.mark.parametrize("case", SLOW_GROUPS[2], ids=name)
    def test_identical(self, case):
        check(case)


@pytest.mark.slow
class TestSlowD:
    @pytest.mark.parametrize("case", SLOW_GROUPS[3], ids=name)
    def test_identical(self, case):
        check(case)


def test_every_case_recorded_and_every_record_a_case():
    cases = {c.name for c in FAST + SLOW}
    assert len(cases) == len(FAST + SLOW), "two cases share a name"
    assert cases == set(RECORDED), (f"not recorded: {sorted(cases - set(RECORDED))}; "
                                    f"recorded, no case: {sorted(set(RECORDED) - cases)}")


# -- the comparison fails when it should ------------------------------------------------

SHELF = next(c for c in FAST if c.name == "path-stretch_shelf-11-8")


@pytest.fixture(scope="module")
def shelf_run(tmp_path_factory):
    """The stretch_shelf corner (about 2 s), its folder kept."""
    keep = tmp_path_factory.mktemp("identity")
    return run_case(SHELF, FIXTURES, keep=keep), keep / SHELF.name


def edited(folder: Path, tmp_path: Path, name: str, old: bytes, new: bytes) -> Path:
    """A copy of ``folder`` with the first ``old`` of file ``name`` replaced by ``new``."""
    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    data = (copy / name).read_bytes()
    assert old in data
    (copy / name).write_bytes(data.replace(old, new, 1))
    return copy


def redigest(result, folder: Path):
    """A copy of ``result`` with the digests of ``folder``'s outputs."""
    names = [p.relative_to(folder).as_posix() for p in folder.rglob("*")
             if p.is_file() and p.name != Path(SHELF.part).name]
    files, normalised = digest_outputs(SHELF, folder, names)
    return replace(result, files=files, normalised=normalised)


def test_the_recorded_run_matches(shelf_run):
    result, _ = shelf_run
    assert compare(RECORDED[SHELF.name], result) == []


def test_one_gcode_coordinate_changed_is_reported(shelf_run, tmp_path):
    result, folder = shelf_run
    text = (folder / "program.ngc").read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("G1 X"))
    x = line.split()[1]                           # e.g. X8: one written coordinate
    changed = f"{x}1" if "." in x else f"{x}.0001"
    copy = edited(folder, tmp_path, "program.ngc", line.encode(),
                  line.replace(x, changed, 1).encode())
    diffs = compare(RECORDED[SHELF.name], redigest(result, copy))
    assert len(diffs) == 1
    assert diffs[0].startswith(f"{SHELF.name}: program.ngc: CHANGED"), diffs


def test_one_json_digit_changed_is_reported(shelf_run, tmp_path):
    result, folder = shelf_run
    data = (folder / "program.json").read_bytes()
    start = data.index(b'"points":[[') + len(b'"points":[[')
    end = data.index(b",", start)                 # the first point's x, full precision
    x = data[start:end]
    last = x[-1:]
    other = b"1" if last != b"1" else b"2"
    copy = edited(folder, tmp_path, "program.json", b'"points":[[' + x,
                  b'"points":[[' + x[:-1] + other)
    diffs = compare(RECORDED[SHELF.name], redigest(result, copy))
    assert diffs == [diffs[0]] and f"{SHELF.name}: program.json: CHANGED" in diffs[0]


def test_a_missing_or_extra_file_or_exit_code_is_reported(shelf_run, tmp_path):
    result, folder = shelf_run
    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    (copy / "program.ngc").rename(copy / "other.ngc")
    diffs = compare(RECORDED[SHELF.name], redigest(result, copy))
    assert any("program.ngc: recorded but not written now" in d for d in diffs)
    assert any("other.ngc: written now but not recorded" in d for d in diffs)
    assert any("exit codes [3]" in d
               for d in compare(RECORDED[SHELF.name], replace(result, exits=[3])))


def test_check_prints_changed_and_exits_1(shelf_run, tmp_path, monkeypatch, capsys):
    """``python -m benchmarks identity --check``: OK and 0 when the digests match, CHANGED
    (naming the file) and 1 when one differs."""
    result, _ = shelf_run
    monkeypatch.setattr(identity, "run_case", lambda case, base, **kw: result)
    doc = read_digests(DIGESTS)
    good = {**doc, "cases": {SHELF.name: RECORDED[SHELF.name]}}
    bad_case = {**RECORDED[SHELF.name],
                "files": {**RECORDED[SHELF.name]["files"], "program.json": "0" * 64}}
    bad = {**doc, "cases": {SHELF.name: bad_case}}
    argv = ["--tier", "fast", "--only", SHELF.name, "--check"]
    for digests, code, word in ((good, 0, "OK"), (bad, 1, "CHANGED")):
        path = tmp_path / f"{word}.json"
        path.write_text(json.dumps(digests))
        assert identity.main(argv + [str(path)]) == code
        out = capsys.readouterr().out
        assert out.startswith(f"{word:8s} {SHELF.name}"), out
    assert "program.json: CHANGED" in out


def test_batch_normalisers(tmp_path):
    summary = (b'{"format": "cadcnc-batch-summary", "version": 1, "cadcnc": "0.1.0", '
               b'"exit": 0, "records": [{"part": "a", "seconds": 0.79, "worker": "vm:1", '
               b'"cpu_seconds": 0.5, "cuts": 1}]}')
    drop, _ = NORMALISERS["batch-summary"]
    assert drop(summary, tmp_path) == (b'{\n "exit": 0,\n "format": "cadcnc-batch-summary",'
                                       b'\n "records": [\n  {\n   "cuts": 1,\n   "part": '
                                       b'"a"\n  }\n ],\n "version": 1\n}')
    folder, _ = NORMALISERS["folder"]
    source = b'"source":"' + str(tmp_path).encode() + b'/a.step"'
    assert folder(source, tmp_path) == b'"source":"a.step"'
