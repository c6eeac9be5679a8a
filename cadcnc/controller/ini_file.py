"""A LinuxCNC INI file read as LinuxCNC reads it (no OCCT, no LinuxCNC import).

LinuxCNC's reader (``IniFile::Find`` in ``src/libnml/inifile/inifile.cc``, behind
``inivar`` and the Python ``linuxcnc.ini``) scans the file from the top for every value:

- the section is the **first** line that starts (after blanks) with ``[NAME]``; a later
  ``[NAME]`` is never read;
- the key is the **first** line of that section that starts with ``KEY`` followed by a
  blank or ``=``; the search stops at the next line starting with ``[``;
- the value is the text after ``=``, blanks (and a DOS ``\\r``) stripped at both ends;
  a comment after a value stays in it (a number is then read by ``sscanf("%lf")``: its
  leading number, the rest ignored);
- lines whose first non-blank character is ``#`` or ``;`` are comments; a line ending
  in ``\\`` continues on the next; a ``\\r`` that does not end a line is an error.

``#INCLUDE FILE`` lines are expanded before any of that by the ``linuxcnc`` launcher
(``handle_includes``: FILE relative to the INI's folder, ``~`` and ``$VAR`` expanded, its
lines pasted in place, not expanded again). :class:`IniFile` does the same, and refuses
an included file it cannot read (the launcher only prints a note and goes on).

:meth:`IniFile.repeats` names what LinuxCNC silently ignores: a repeated key of the
section read, a repeated section (each with both line numbers).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from ..core.errors import InputError

MAX_EXTEND_LINES = 20   # LinuxCNC's limit on "\" continuations of one line
NUMBER = re.compile(r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)",
                    re.IGNORECASE)
"""The leading number ``sscanf("%lf")`` reads (decimal, inf, nan)."""


@dataclass(frozen=True)
class Line:
    """One logical line: its text (continuations joined), where it is (file, 1-based)."""

    text: str
    source: str
    number: int

    @property
    def where(self) -> str:
        return f"{self.source}:{self.number}"


def _physical_lines(path: Path) -> list[str]:
    try:
        data = path.read_bytes()
    except OSError as e:
        raise InputError(f"{path}: cannot read the machine INI file ({e.strerror or e})") \
            from None
    text = data.decode("utf-8", errors="replace")
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    for k, line in enumerate(lines, 1):
        if "\r" in line[:-1]:
            raise InputError(f"{path}:{k}: a carriage return inside a line (LinuxCNC refuses "
                             "the file: 'ambiguous carriage returns')")
    return [line[:-1] if line.endswith("\r") else line for line in lines]


def _expanded(path: Path) -> list[tuple[str, str, int]]:
    """(text, source, line number) of every physical line, #INCLUDEs pasted in place."""
    out = []
    for k, line in enumerate(_physical_lines(path), 1):
        words = line.split(None, 1)
        if words and words[0] == "#INCLUDE":
            if len(words) < 2:
                raise InputError(f"{path}:{k}: #INCLUDE without a file name")
            name = os.path.expandvars(os.path.expanduser(words[1].strip()))
            inc = Path(name) if os.path.isabs(name) else path.parent / name
            if not inc.is_file():
                raise InputError(f"{path}:{k}: #INCLUDE {words[1].strip()}: cannot read "
                                 f"{inc} (LinuxCNC would go on without it)")
            out += [(t, str(inc), n) for n, t in enumerate(_physical_lines(inc), 1)]
        else:
            out.append((line, str(path), k))
    return out


def _logical(physical: list[tuple[str, str, int]]) -> list[Line]:
    """Lines ending in a backslash joined to the next (at most MAX_EXTEND_LINES)."""
    out, parts, start = [], [], None
    for text, source, number in physical:
        if start is None:
            start = (source, number)
        if text.endswith("\\"):
            parts.append(text[:-1])
            if len(parts) > MAX_EXTEND_LINES:
                raise InputError(f"{source}:{number}: more than {MAX_EXTEND_LINES} backslash "
                                 "continuations (LinuxCNC refuses the line)")
            continue
        out.append(Line("".join(parts) + text, *start))
        parts, start = [], None
    if parts:
        out.append(Line("".join(parts), *start))
    return out


def _content(text: str) -> str | None:
    """The text from its first non-blank character, None for a blank or comment line."""
    stripped = text.lstrip(" \t\r\n")
    return None if not stripped or stripped[0] in "#;" else stripped


def _value(content: str, key: str) -> str | None:
    """The value when ``content`` is ``key`` then a blank or '=' (else None); '' for a key
    with no value (LinuxCNC: not found)."""
    if not content.startswith(key) or content[len(key):len(key) + 1] not in (" ", "\t", "="):
        return None
    rest = content[len(key):]
    if "=" not in rest:
        return ""
    return rest.split("=", 1)[1].strip(" \t\r\n")


class IniFile:
    """The lines of an INI file (``#INCLUDE`` expanded), read as LinuxCNC reads them."""

    def __init__(self, path):
        self.path = Path(path)
        self.lines = _logical(_expanded(self.path))

    def _sections(self, section: str) -> list[int]:
        """Indices of the lines that open ``[section]`` (LinuxCNC reads the first only)."""
        head = f"[{section}]"
        return [k for k, line in enumerate(self.lines)
                if (c := _content(line.text)) is not None and c.startswith(head)]

    def _block(self, start: int):
        for line in self.lines[start + 1:]:
            c = _content(line.text)
            if c is None:
                continue
            if c.startswith("["):
                return
            yield line, c

    def has_section(self, section: str) -> bool:
        return bool(self._sections(section))

    def find(self, section: str, key: str) -> tuple[str | None, Line | None]:
        """LinuxCNC's value of ``[section] key`` and its line; (None, None) when it finds
        none (no section, no key in the first such section, or nothing after '=')."""
        opened = self._sections(section)
        if not opened:
            return None, None
        for line, c in self._block(opened[0]):
            value = _value(c, key)
            if value is not None:
                return (value or None), line
        return None, None

    def repeats(self, section: str, key: str) -> list[str]:
        """What LinuxCNC ignores around ``[section] key``: a later ``key`` in the section
        read, and the key in a repeated ``[section]``; one sentence each, both lines named."""
        opened = self._sections(section)
        if not opened:
            return []
        value, first = self.find(section, key)
        said = []
        head = self.lines[opened[0]]
        for other in opened[1:]:
            for line, c in self._block(other):
                if _value(c, key) is not None:
                    said.append(f"{line.where}: [{section}] {key} is in a repeated section "
                                f"[{section}] (line {self.lines[other].number}; the first is "
                                f"{head.where}): LinuxCNC reads only the first section, and "
                                "so does cadcnc: "
                                + (f"{key} = {value} ({first.where})" if first else
                                   f"{key} is not in it"))
        if first is None:
            return said
        later = False
        for line, c in self._block(opened[0]):
            if line is first:
                later = True
            elif later and _value(c, key) is not None:
                said.insert(0, f"{line.where}: [{section}] {key} = {_value(c, key)} repeats "
                               f"{first.where} ({key} = {value}): LinuxCNC uses the first, "
                               "and so does cadcnc")
        return said


def leading_number(text: str) -> tuple[float | None, str]:
    """The number ``sscanf("%lf")`` reads at the start of ``text`` (None: none) and the
    text after it (which LinuxCNC ignores)."""
    found = NUMBER.match(text)
    if found is None:
        return None, text
    return float(found.group(0)), text[found.end():].strip()
