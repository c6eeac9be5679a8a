"""The APT-like language's syntax: tokens, statements, parser (grammar in docs/notes/apt.md).

Pure syntax: no file system, no geometry, no ranges. A statement carries its values in
user units (mm, mm/min, s) and, in ``where``, the (line, column) of each value, so that
the program stage (:mod:`cadcnc.apt.program_entries`) can report a value the :class:`~cadcnc.core.job.Job`
refuses at the place it was written. The checks here are the grammar's own: token kinds,
the period's unit, face and edge numbers being whole numbers, edges numbered from 1.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from ..core.errors import ProgramSyntaxError
from ..core.units import DURATION_UNITS

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
MODAL = ("PARTNO", "CUTTER", "FEED", "FEDRAT", "PERIOD")  # KEYWORD/...


@dataclass(frozen=True)
class Token:
    kind: str  # number, name, string, punct, end (of statement), eof
    text: str
    line: int
    column: int
    value: object = None
    unit: str = ""

    @property
    def at(self) -> tuple[int, int]:
        return self.line, self.column


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
    """IS or IE as written: a point (mm) or the shared edge's end (``edge``: 1-based)."""

    point: tuple[float, float, float] | None = None
    edge: int | None = None


@dataclass(frozen=True)
class Statement:
    """One statement. ``args`` by keyword (user units):

    PARTNO: title; PART: file; CUTTER: radius, allowance (mm); FEED: feed (mm/min);
    PERIOD: period (s); PATH: name, faces (two ints), start, end (:class:`Endpoint`).
    ``where``: (line, column) of each argument as written.
    """

    keyword: str  # PARTNO, PART, CUTTER, FEED, PERIOD, PATH, FINI
    line: int
    column: int
    args: dict = field(default_factory=dict)
    where: dict = field(default_factory=dict)


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

    def string(self, what: str) -> Token:
        tok = self.tok
        if tok.kind != "string":
            raise self.error(f"expected {what}, found {_show(tok)}")
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
        elif kw in MODAL:
            self.expect("/", f" after {kw}")
            st = getattr(self, "_" + ("feed" if kw == "FEDRAT" else kw.lower()))(tok)
        elif self.tok.text == "=":
            self.next()
            if kw == "PART":
                s = self.string("the part file as a quoted string")
                st = Statement("PART", *tok.at, {"file": s.value}, {"file": s.at})
            else:
                st = self._path(tok)
        else:
            raise self.error(f"unknown statement {tok.text!r}: expected PART, PARTNO, CUTTER, "
                             f"FEED, PERIOD, FINI or NAME = P/[...]", tok)
        self.end_of_statement()
        return st

    def _partno(self, tok: Token) -> Statement:
        s = self.string("a quoted title after PARTNO/")
        return Statement("PARTNO", *tok.at, {"title": s.value}, {"title": s.at})

    def _cutter(self, tok: Token) -> Statement:
        nums: dict[str, Token] = {}
        while True:
            name = self.tok
            if name.kind != "name" or name.value not in ("R", "C"):
                raise self.error(f"expected R=radius or C=allowance (mm), found {_show(name)}")
            self.next()
            if name.value in nums:
                raise self.error(f"{name.value} given twice", name)
            self.expect("=", f" after {name.value}")
            nums[name.value] = self.number(f"{name.value} in mm")
            if self.tok.text != ",":
                break
            self.next()
        if "R" not in nums:
            raise self.error("CUTTER needs R=radius (mm)", tok)
        args = {"radius": nums["R"].value, "allowance": 0.0}
        where = {"radius": nums["R"].at, "allowance": nums.get("C", nums["R"]).at}
        if "C" in nums:
            args["allowance"] = nums["C"].value
        return Statement("CUTTER", *tok.at, args, where)

    def _feed(self, tok: Token) -> Statement:
        num = self.number("a feed in mm/min")
        return Statement("FEED", *tok.at, {"feed": num.value}, {"feed": num.at})

    def _period(self, tok: Token) -> Statement:
        num = self.number("a period with a unit (4ms, 0.004s, 250us)", unit_ok=True)
        if not num.unit:
            raise self.error(f"period {num.text!r} has no unit; write 4ms, 0.004s or 250us", num)
        if num.unit not in DURATION_UNITS:
            raise self.error(f"unknown period unit {num.unit!r}; use s, ms or us", num)
        return Statement("PERIOD", *tok.at, {"period": num.value * DURATION_UNITS[num.unit]},
                         {"period": num.at})

    def _path(self, name: Token) -> Statement:
        p = self.tok
        if p.kind != "name" or p.value != "P":
            raise self.error(f"expected P/[S1, S2, IS, IE] after '{name.text} =', "
                             f"found {_show(p)}")
        self.next()
        self.expect("/", " after P")
        self.expect("[")
        where = {"S1": self.tok.at}
        faces = [self._face("S1")]
        self.expect(",", " between S1 and S2")
        where["S2"] = self.tok.at
        faces.append(self._face("S2"))
        self.expect(",", " then IS (start: a point (x, y, z) or EDGE)")
        where["start"] = self.tok.at
        start = self._endpoint("IS")
        self.expect(",", " then IE (end: a point (x, y, z) or EDGE)")
        where["end"] = self.tok.at
        end = self._endpoint("IE")
        self.expect("]", " closing P/[S1, S2, IS, IE]")
        return Statement("PATH", *name.at,
                         {"name": name.text, "faces": tuple(faces), "start": start, "end": end},
                         where)

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
    """Statements of a program; :class:`ProgramSyntaxError` names line and column.

    Syntax only: a value out of range (R < 0, FEED/0) is refused when the program's jobs
    are built (:func:`cadcnc.apt.program_entries.entries`), at the value's line and column.
    """
    return _Parser(tokenize(text, source), source).program()
