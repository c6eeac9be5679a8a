"""A program's statements as machining jobs: one :class:`ProgramEntry` per PATH statement.

CUTTER, FEED and PERIOD are modal (they apply to the paths after them); PART may change
between paths, and a relative part file is relative to the program's folder. Every value
is validated by the :class:`~cadcnc.core.job.Job` record itself (its :class:`~cadcnc.core.job.Tool`
and :func:`~cadcnc.core.job.check_number`), where the statement is met; a value it refuses
comes back as a :class:`ProgramSyntaxError` at the value's line and column. Nothing here
reads a part: :func:`cadcnc.apt.execute.check` does that.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from ..core.errors import InputError, ProgramSyntaxError
from ..core.job import Job, PairPath, Tool, check_number, check_point
from ..core.tolerances import DEFAULT, Tolerances
from .grammar import Endpoint, Statement, parse

# the modal settings a PATH needs, and the statement that gives each
_NEEDS = (("source", "PART = 'file.step'"), ("tool", "CUTTER/R=..."), ("feed", "FEED/..."),
          ("period", "PERIOD/..."))
# a Job's error message starts with the parameter's name: where that value was written
_WHERE = {"radius": "radius", "allowance": "allowance", "feed": "feed", "period": "period",
          "face": "S1", "start": "start", "end": "end"}
_CALLERS = ("clearance",)  # parameters the caller gives, not the program


@dataclass(frozen=True)
class ProgramEntry:
    """One PATH statement: its name, line and column, and the :class:`Job` it asks for.

    The job holds the modal settings in force (tool, feed, period, the part file as its
    ``source``), the two faces and the IS/IE ends. ``EDGE, EDGE`` is the job's own default
    (no start, no end: the ends of the shared concave edge ``job.operation.edge``). When
    only one of IS/IE is an EDGE end, ``pending`` holds both as written and the job has no
    start or end yet: :func:`cadcnc.apt.execute.check` replaces the EDGE end by the edge's
    point, once the part is loaded, and clears ``pending``.
    """

    name: str
    line: int
    job: Job
    pending: tuple[Endpoint, Endpoint] | None = None
    column: int = 1

    @property
    def on_edge(self) -> bool:
        """True when an end is an EDGE end: the faces must share that concave edge."""
        return self.pending is not None or self.job.operation.start is None


@contextmanager
def _located(st: Statement, source: str):
    """A value the Job refuses, as a ProgramSyntaxError where the program wrote it."""
    try:
        yield
    except ProgramSyntaxError:
        raise
    except InputError as e:
        key = str(e).split(" ", 1)[0]
        if key in _CALLERS:
            raise
        line, column = st.where.get(_WHERE.get(key), (st.line, st.column))
        raise ProgramSyntaxError(str(e), line, column, source) from None


def _part_file(name: str, base_dir) -> str:
    f = Path(name).expanduser()
    return os.path.normpath(f if f.is_absolute() else Path(base_dir) / f)


def _entry(st: Statement, state: dict, source: str, tolerances: Tolerances,
           clearance) -> ProgramEntry:
    a = st.args
    for key, stmt in _NEEDS:
        if state[key] is None:
            raise ProgramSyntaxError(f"PATH {a['name']} needs {stmt} before it",
                                     st.line, st.column, source)
    s, e = a["start"], a["end"]
    if s.edge and e.edge and s.edge != e.edge:
        raise ProgramSyntaxError(f"IS names EDGE({s.edge}) but IE names EDGE({e.edge})",
                                 st.line, st.column, source)
    pending = None
    if bool(s.edge) != bool(e.edge):  # one EDGE end: its point is known once loaded
        pending = (s, e)
        given = ("start", s.point) if e.edge else ("end", e.point)
        check_point(*given)
    explicit = not (s.edge or e.edge)
    op = PairPath(faces=a["faces"], start=s.point if explicit else None,
                  end=e.point if explicit else None, edge=(s.edge or e.edge or 1) - 1)
    job = Job(state["tool"], state["feed"], state["period"], op, source=state["source"],
              clearance=clearance, tolerances=tolerances)
    return ProgramEntry(a["name"], st.line, job, pending, st.column)


def entries(statements: list[Statement], base_dir=".", source: str = "<program>",
            tolerances: Tolerances = DEFAULT, clearance: float | None = None
            ) -> list[ProgramEntry]:
    """The PATH statements as validated jobs; a missing setting is an error at its line.

    ``base_dir``: the folder relative part files are resolved against. ``tolerances`` and
    ``clearance`` (mm, None for the part's top plus a margin) go into every job.
    """
    state = dict.fromkeys(("source", "tool", "feed", "period"))
    out = []
    for st in statements:
        a = st.args
        with _located(st, source):
            if st.keyword == "PART":
                state["source"] = _part_file(a["file"], base_dir)
            elif st.keyword == "CUTTER":
                state["tool"] = Tool(a["radius"], a["allowance"])
            elif st.keyword == "FEED":
                state["feed"] = check_number("feed", a["feed"], "mm/min")
            elif st.keyword == "PERIOD":
                state["period"] = check_number("period", a["period"], "s")
            elif st.keyword == "PATH":
                out.append(_entry(st, state, source, tolerances, clearance))
    if not out:
        raise ProgramSyntaxError("the program has no PATH = P/[...] statement",
                                 statements[-1].line if statements else 1, 1, source)
    return out


def title(statements: list[Statement]) -> str:
    """The PARTNO title ('' without one)."""
    return next((s.args["title"] for s in statements if s.keyword == "PARTNO"), "")


def read_program(file, tolerances: Tolerances = DEFAULT, clearance: float | None = None
                 ) -> tuple[list[ProgramEntry], str]:
    """The entries of the program in ``file`` (syntax and values checked, no part loaded)
    and its title. Part files are relative to the program's folder."""
    file = Path(file)
    try:
        text = file.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{file}: no such file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{file}: cannot read the program ({e})") from None
    statements = parse(text, str(file))
    return entries(statements, file.parent, str(file), tolerances, clearance), title(statements)
