"""The APT-like part program: parse, check, and execute ``PATH = P/[S1, S2, IS, IE]``.

The format (grammar in docs/notes/apt.md) is ours, in the spirit of the paper's one-statement
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

Three stages, each complete before the next, one module each:

- :mod:`~cadcnc.apt.grammar`: :func:`parse`, text to statements (syntax only; errors
  name line and column);
- :mod:`~cadcnc.apt.program_entries`: :func:`entries` / :func:`read_program`, statements to one
  :class:`ProgramEntry` per PATH (its name, line and validated :class:`~cadcnc.core.job.Job`);
- :mod:`~cadcnc.apt.execute`: :func:`check` loads the parts and checks face numbers and
  EDGE ends before any path is computed, then :func:`run_job` / :func:`stream_job` per
  entry.
"""

from __future__ import annotations

from .execute import check, run_job, stream_job
from .grammar import Endpoint, Statement, Token, parse, tokenize
from .program_entries import ProgramEntry, entries, read_program, title

__all__ = ["Endpoint", "ProgramEntry", "Statement", "Token", "check", "entries", "parse",
           "read_program", "run_job", "stream_job", "title", "tokenize"]
