"""The APT-like part program: parse, check, and execute ``PATH = P/[S1, S2, IS, IE]``.

The format (grammar in docs/cli.md) is ours, in the spirit of the paper's one-statement
part program::

    $$ pencil path around the boss
    PARTNO/'boss fillet'
    PART = 'bspline_boss.step'
    CUTTER/R=3, C=0
    FEED/1500
    PERIOD/4ms
    BOSS = P/[F4, F5, EDGE, EDGE]
    FINI

Keywords are case-insensitive; ``$$`` starts a comment; a statement ends at the end of
its line unless a bracket or parenthesis is still open. CUTTER, FEED and PERIOD are modal
(they apply to the paths after them); PART may change between paths. Relative file names
are relative to the program's folder.

Three stages, each complete before the next: :func:`parse` (syntax; errors name line and
column), :func:`check` (loads the parts, checks face numbers and face pairs before any
path is computed), then :func:`run_job` / :func:`stream_job` per path.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import CadcncError, InputError, ProgramSyntaxError
from ..units import DURATION_UNITS

_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_TOKEN = re.compile(rf"""
    (?P<comment>\$\$[^\n]*)
  | (?P<newline>\n)
  | (?P<space>[ \t\r]+)
  | (?P<number>{_NUMBER}(?P<unit>[A-Za-zµ]+)?)
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<string>'[^'\n]*'|"[^"\n]*")
  | (?P<punct>[/=,\[\]()])
""", re.VERBOSE)


@dataclass(frozen=True)
class Token:
    kind: str  # number, name, string, punct, end (of statement), eof
    text: str
    line: int
    column: int
    value: object = None
    unit: str = ""


def tokenize(text: str, source: str = "<program>") -> list[Token]:
    """Tokens with 1-based line and column; newlines inside brackets are ignored."""
    tokens: list[Token] = []
    line, line_start, depth, pos = 1, 0, 0, 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        col = pos - line_start + 1
        if not m:
            raise ProgramSyntaxError(f"unexpected character {text[pos]!r}", line, col, source)
        kind = m.lastgroup if m.lastgroup != "unit" else "number"
        s = m.group()
        if kind == "newline":
            if depth == 0:
                tokens.append(Token("end", "end of line", line, col))
            line, line_start = line + 1, m.end()
        elif kind == "number":
            unit = m.group("unit") or ""
            tokens.append(Token("number", s, line, col, float(s[:len(s) - len(unit)]), unit))
        elif kind == "name":
            tokens.append(Token("name", s, line, col, s.upper()))
        elif kind == "string":
            tokens.append(Token("string", s, line, col, s[1:-1]))
        elif kind == "punct":
            depth += s in "[("
            depth -= s in "])" and depth > 0
            tokens.append(Token("punct", s, line, col, s))
        pos = m.end()
    col = pos - line_start + 1
    tokens.append(Token("end", "end of file", line, col))
    tokens.append(Token("eof", "end of file", line, col))
    return tokens


# -- statements ------------------------------------------------------------------------------
@dataclass(frozen=True)
class Endpoint:
    """IS or IE: a point (mm) or the shared edge's end (``edge``: 1-based edge index)."""

    point: tuple[float, float, float] | None = None
    edge: int | None = None


@dataclass(frozen=True)
class Statement:
    keyword: str  # PARTNO, PART, CUTTER, FEED, PERIOD, PATH, FINI
    line: int
    column: int
    args: dict = field(default_factory=dict)


class _Parser:
    def __init__(self, tokens: list[Token], source: str):
        self.tokens, self.pos, self.source = tokens, 0, source

    @property
    def tok(self) -> Token:
        return self.tokens[self.pos]

    def error(self, message: str, tok: Token | None = None):
        tok = tok or self.tok
        return ProgramSyntaxError(message, tok.line, tok.column, self.source)

    def next(self) -> Token:
        tok = self.tok
        self.pos += 1
        return tok

    def expect(self, text: str, what: str = "") -> Token:
        tok = self.tok
        if tok.kind != "punct" or tok.text != text:
            raise self.error(f"expected '{text}'{what}, found {_show(tok)}")
        return self.next()

    def number(self, what: str, unit_ok: bool = False) -> Token:
        tok = self.tok
        if tok.kind != "number":
            raise self.error(f"expected {what}, found {_show(tok)}")
        if tok.unit and not unit_ok:
            raise self.error(f"{what}: unexpected unit {tok.unit!r}")
        return self.next()

    def end_of_statement(self):
        if self.tok.kind != "end":
            raise self.error(f"expected end of statement, found {_show(self.tok)}")
        self.next()

    def program(self) -> list[Statement]:
        out: list[Statement] = []
        finished = None
        while self.tok.kind != "eof":
            if self.tok.kind == "end":
                self.next()
                continue
            if finished is not None:
                raise self.error(f"statement after FINI (line {finished.line})")
            st = self.statement()
            out.append(st)
            if st.keyword == "FINI":
                finished = st
        return out

    def statement(self) -> Statement:
        tok = self.tok
        if tok.kind != "name":
            raise self.error(f"expected a statement (PART, CUTTER, FEED, PERIOD, NAME = P/[...], "
                             f"FINI), found {_show(tok)}")
        self.next()
        kw = tok.value
        if kw == "FINI":
            st = Statement("FINI", tok.line, tok.column)
        elif kw in ("PARTNO", "CUTTER", "FEED", "FEDRAT", "PERIOD"):
            self.expect("/", f" after {kw}")
            st = getattr(self, "_" + ("feed" if kw == "FEDRAT" else kw.lower()))(tok)
        elif self.tok.text == "=":
            self.next()
            if kw == "PART":
                s = self.tok
                if s.kind != "string":
                    raise self.error(f"expected the part file as a quoted string, found {_show(s)}")
                self.next()
                st = Statement("PART", tok.line, tok.column, {"file": s.value})
            else:
                st = self._path(tok)
        else:
            raise self.error(f"unknown statement {tok.text!r}: expected PART, PARTNO, CUTTER, "
                             f"FEED, PERIOD, FINI or NAME = P/[...]", tok)
        self.end_of_statement()
        return st

    def _partno(self, tok: Token) -> Statement:
        s = self.tok
        if s.kind != "string":
            raise self.error(f"expected a quoted title after PARTNO/, found {_show(s)}")
        self.next()
        return Statement("PARTNO", tok.line, tok.column, {"title": s.value})

    def _cutter(self, tok: Token) -> Statement:
        args = {}
        while True:
            name = self.tok
            if name.kind != "name" or name.value not in ("R", "C"):
                raise self.error(f"expected R=radius or C=allowance (mm), found {_show(name)}")
            self.next()
            if name.value in args:
                raise self.error(f"{name.value} given twice", name)
            self.expect("=", f" after {name.value}")
            num = self.number(f"{name.value} in mm")
            if num.value < 0:
                raise self.error(f"{name.value} must be >= 0 mm", num)
            args[name.value] = num.value
            if self.tok.text != ",":
                break
            self.next()
        if "R" not in args:
            raise self.error("CUTTER needs R=radius (mm)", tok)
        return Statement("CUTTER", tok.line, tok.column,
                         {"radius": args["R"], "allowance": args.get("C", 0.0)})

    def _feed(self, tok: Token) -> Statement:
        num = self.number("a feed in mm/min")
        if not num.value > 0:
            raise self.error("feed must be > 0 mm/min", num)
        return Statement("FEED", tok.line, tok.column, {"feed": num.value})

    def _period(self, tok: Token) -> Statement:
        num = self.number("a period with a unit (4ms, 0.004s, 250us)", unit_ok=True)
        if not num.unit:
            raise self.error(f"period {num.text!r} has no unit; write 4ms, 0.004s or 250us", num)
        if num.unit not in DURATION_UNITS:
            raise self.error(f"unknown period unit {num.unit!r}; use s, ms or us", num)
        if not num.value > 0:
            raise self.error("period must be > 0", num)
        return Statement("PERIOD", tok.line, tok.column,
                         {"period": num.value * DURATION_UNITS[num.unit]})

    def _path(self, name: Token) -> Statement:
        p = self.tok
        if p.kind != "name" or p.value != "P":
            raise self.error(f"expected P/[S1, S2, IS, IE] after '{name.text} =', "
                             f"found {_show(p)}")
        self.next()
        self.expect("/", " after P")
        self.expect("[")
        faces = [self._face("S1")]
        self.expect(",", " between S1 and S2")
        faces.append(self._face("S2"))
        self.expect(",", " then IS (start: a point (x, y, z) or EDGE)")
        start = self._endpoint("IS")
        self.expect(",", " then IE (end: a point (x, y, z) or EDGE)")
        end = self._endpoint("IE")
        self.expect("]", " closing P/[S1, S2, IS, IE]")
        return Statement("PATH", name.line, name.column,
                         {"name": name.text, "faces": tuple(faces), "start": start, "end": end})

    def _face(self, what: str) -> int:
        tok = self.tok
        m = re.fullmatch(r"F(\d+)", tok.text, re.IGNORECASE) if tok.kind == "name" else None
        if m:
            self.next()
            return int(m.group(1))
        if tok.kind == "number" and not tok.unit and tok.value.is_integer():
            self.next()
            return int(tok.value)
        raise self.error(f"expected face {what} as F<number> (e.g. F4), found {_show(tok)}")

    def _endpoint(self, what: str) -> Endpoint:
        tok = self.tok
        if tok.kind == "name" and tok.value == "EDGE":
            self.next()
            if self.tok.text != "(":
                return Endpoint(edge=1)
            self.next()
            num = self.number("an edge number (1, 2, ...)")
            if not (num.value.is_integer() and num.value >= 1):
                raise self.error("edge number must be an integer >= 1", num)
            self.expect(")", " after the edge number")
            return Endpoint(edge=int(num.value))
        if tok.text == "(":
            self.next()
            xyz = []
            for axis in "xyz":
                xyz.append(self.number(f"{axis} coordinate (mm) of {what}").value)
                if axis != "z":
                    self.expect(",", f" after the {axis} coordinate")
            self.expect(")", f" closing the point {what}")
            return Endpoint(point=tuple(xyz))
        raise self.error(f"expected {what} as a point (x, y, z) or EDGE, found {_show(tok)}")


def _show(tok: Token) -> str:
    return tok.text if tok.kind in ("end", "eof") else repr(tok.text)


def parse(text: str, source: str = "<program>") -> list[Statement]:
    """Statements of a program; :class:`ProgramSyntaxError` names line and column."""
    return _Parser(tokenize(text, source), source).program()


# -- jobs ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PathJob:
    """One PATH statement with the modal settings in force, units mm, mm/min, s."""

    name: str
    line: int
    part_file: str
    faces: tuple[int, int]
    radius: float
    allowance: float
    feed: float
    period: float
    start: tuple | Endpoint | None = None  # a point, or an EDGE end until check()
    end: tuple | Endpoint | None = None
    edge: int = 0  # 0-based index among the pair's concave shared edges
    title: str = ""

    def kwargs(self) -> dict:
        return dict(radius=self.radius, allowance=self.allowance, feed=self.feed,
                    period=self.period, start=self.start, end=self.end, edge=self.edge)


def jobs(statements: list[Statement], base_dir=".", source: str = "<program>") -> list[PathJob]:
    """The PATH statements with their settings; a missing setting is an error at its line."""
    state = {"part": None, "radius": None, "allowance": 0.0, "feed": None, "period": None,
             "title": ""}
    out = []
    for st in statements:
        a = st.args
        if st.keyword == "PARTNO":
            state["title"] = a["title"]
        elif st.keyword == "PART":
            f = Path(a["file"]).expanduser()
            state["part"] = os.path.normpath(f if f.is_absolute() else Path(base_dir) / f)
        elif st.keyword == "CUTTER":
            state.update(radius=a["radius"], allowance=a["allowance"])
        elif st.keyword in ("FEED", "PERIOD"):
            state.update(a)
        elif st.keyword == "PATH":
            for key, stmt in (("part", "PART = 'file.step'"), ("radius", "CUTTER/R=..."),
                              ("feed", "FEED/..."), ("period", "PERIOD/...")):
                if state[key] is None:
                    raise ProgramSyntaxError(f"PATH {a['name']} needs {stmt} before it",
                                             st.line, st.column, source)
            s, e = a["start"], a["end"]
            if s.edge and e.edge and s.edge != e.edge:
                raise ProgramSyntaxError(f"IS names EDGE({s.edge}) but IE names EDGE({e.edge})",
                                         st.line, st.column, source)
            out.append(PathJob(a["name"], st.line, state["part"], a["faces"], state["radius"],
                               state["allowance"], state["feed"], state["period"],
                               s if s.edge else s.point, e if e.edge else e.point,
                               (s.edge or e.edge or 1) - 1, state["title"]))
    if not out:
        raise ProgramSyntaxError("the program has no PATH = P/[...] statement",
                                 statements[-1].line if statements else 1, 1, source)
    return out


def read_program(file) -> tuple[list[PathJob], str]:
    """Jobs of the program in ``file`` (syntax checked, nothing loaded) and its title."""
    file = Path(file)
    try:
        text = file.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{file}: no such file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{file}: cannot read the program ({e})") from None
    statements = parse(text, str(file))
    return jobs(statements, file.parent, str(file)), next(
        (s.args["title"] for s in statements if s.keyword == "PARTNO"), "")


def _at(job: PathJob, e: CadcncError, source: str) -> CadcncError:
    """The same kind of error, prefixed with the program line of the PATH statement."""
    try:
        err = type(e)(f"{source}:{job.line}: PATH {job.name}: {e}")
    except TypeError:
        err = InputError(f"{source}:{job.line}: PATH {job.name}: {e}")
    return err


def check(job_list: list[PathJob], source: str = "<program>", load=None):
    """Load the parts and check every face pair before any path is computed.

    Returns [(job, part)] with EDGE ends resolved (a lone EDGE end becomes the edge's
    point). Library errors come back prefixed with the PATH statement's line.
    """
    import numpy as np

    from ..geometry.part import load_step
    from ..ops.pair_path import shared_edge_for

    load = load or load_step
    parts: dict[str, object] = {}
    out = []
    for job in job_list:
        try:
            if job.part_file not in parts:
                parts[job.part_file] = load(job.part_file)
            part = parts[job.part_file]
            s1, s2 = part.face(job.faces[0]), part.face(job.faces[1])
            start, end = job.start, job.end
            if isinstance(start, Endpoint) or isinstance(end, Endpoint):
                e = shared_edge_for(s1, s2, job.edge)
                if isinstance(start, Endpoint) and isinstance(end, Endpoint):
                    start = end = None
                else:
                    if isinstance(start, Endpoint):
                        start = tuple(np.asarray(e.start, float))
                    if isinstance(end, Endpoint):
                        end = tuple(np.asarray(e.end, float))
            out.append((replace(job, start=start, end=end), part))
        except CadcncError as e:
            raise _at(job, e, source) from e
    return out


def run_job(job: PathJob, part, progress=None, source: str = "<program>"):
    """The :class:`~cadcnc.toolpath.Toolpath` of one checked job."""
    from ..ops.pair_path import intersection_path

    try:
        return intersection_path(part.face(job.faces[0]), part.face(job.faces[1]),
                                 progress=progress, **job.kwargs())
    except CadcncError as e:
        raise _at(job, e, source) from e


def stream_job(job: PathJob, part, source: str = "<program>"):
    """(stepper, increments): the stepper and a generator of its per-period (dx, dy, dz)."""
    from ..ops.pair_path import make_stepper

    try:
        stepper = make_stepper(part.face(job.faces[0]), part.face(job.faces[1]),
                               record=False, **job.kwargs())
    except CadcncError as e:
        raise _at(job, e, source) from e

    def increments():
        while (dp := stepper.step()) is not None:
            yield dp

    return stepper, increments()
