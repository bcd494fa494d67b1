"""The line of a device profile that a dotted key (``serial.baudrate``,
``operations.dispense.command``) comes from, so a profile error reads ``file:line: key``
(a TOML syntax error ``file:line:``) and an editor can jump to it.

tomllib keeps no positions, so the text is scanned for table headers and ``key =`` lines.
A key written inside an inline table (``emulate = { reply = … }``) or never written (a
required key that is missing) is placed at the nearest enclosing key or table that is.
"""

from __future__ import annotations

import re
from pathlib import Path

from opspec.errors import BindingError, SourceLocation

__all__ = ["key_line", "located"]

#: where tomllib says a syntax error is: "… (at line 14, column 18)"
_SYNTAX_AT = re.compile(r"\(at line (\d+), column \d+\)")

_HEADER = re.compile(r"^\s*\[\[?\s*(?P<path>[^\[\]]+?)\s*\]\]?\s*(#.*)?$")
_BARE = re.compile(r"[A-Za-z0-9_-]+")


def located(error: BindingError, where: str) -> BindingError:
    """``error`` about the profile file ``where``, placed at its line: the line its key is
    written on (or the nearest written parent's), or a syntax error's line. Unchanged when
    it has a line already, is about another file, or names no line to find."""
    at = error.location
    if at is None or at.line is not None or at.path != where:
        return error
    syntax = _SYNTAX_AT.search(error.message)
    if syntax is not None:
        line: int | None = int(syntax.group(1))
    elif at.key:
        try:
            text = Path(where).read_text(encoding="utf-8")   # just read: it is text
        except (OSError, UnicodeDecodeError):
            return error
        line = key_line(text, at.key)
    else:
        line = None
    if line is None:
        return error
    return BindingError(error.message, location=SourceLocation(at.path, line, at.key),
                        hint=error.hint)


def key_line(text: str, key: str) -> int | None:
    """The 1-based line where ``key`` (dotted, parts unquoted, as the profile loader names
    it) or its nearest written parent is defined in the TOML ``text``; None when neither
    is (a key of the top table that is missing)."""
    lines = _defined_at(text)
    best: tuple[int, int] | None = None        # (length of the matched path, line)
    for path, line in lines.items():
        if (key == path or key.startswith(path + ".")) and (best is None or len(path) > best[0]):
            best = (len(path), line)
    return None if best is None else best[1]


def _defined_at(text: str) -> dict[str, int]:
    """Every table and key path the text writes, with the first line writing it."""
    found: dict[str, int] = {}
    table: list[str] = []
    in_string: str | None = None                # the delimiter of an open multi-line string
    for number, raw in enumerate(text.splitlines(), start=1):
        if in_string is not None:
            if raw.count(in_string) % 2:
                in_string = None
            continue
        header = _HEADER.match(raw)
        if header:
            parts = _split_key(header.group("path"))
            if parts is None:
                continue
            table = parts
            for end in range(1, len(parts) + 1):   # [a.b] also defines a
                found.setdefault(".".join(parts[:end]), number)
            continue
        name, sep, value = _split_assignment(raw)
        if not sep:
            continue
        parts = _split_key(name)
        if parts is None:
            continue
        full = [*table, *parts]
        for end in range(len(table) + 1, len(full) + 1):
            found.setdefault(".".join(full[:end]), number)
        for quotes in ('"""', "'''"):
            if value.count(quotes) % 2:
                in_string = quotes
    return found


def _split_assignment(line: str) -> tuple[str, str, str]:
    """``key = value`` split at the ``=`` that is outside the key's quotes."""
    quote: str | None = None
    for index, char in enumerate(line):
        if quote is not None:
            if char == quote:
                quote = None
        elif char in "\"'":
            quote = char
        elif char == "=":
            return line[:index], "=", line[index + 1:]
        elif char == "#":
            break
    return line, "", ""


def _split_key(text: str) -> list[str] | None:
    """The parts of a dotted TOML key (bare or quoted), or None if it is not one."""
    parts: list[str] = []
    rest = text.strip()
    while rest:
        if rest[0] in "\"'":
            end = rest.find(rest[0], 1)
            if end < 0:
                return None
            parts.append(rest[1:end])
            rest = rest[end + 1:].lstrip()
        else:
            bare = _BARE.match(rest)
            if bare is None:
                return None
            parts.append(bare.group())
            rest = rest[bare.end():].lstrip()
        if rest.startswith("."):
            rest = rest[1:].lstrip()
        elif rest:
            return None
    return parts or None
