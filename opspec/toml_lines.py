"""Where in a TOML file people write a key or a syntax error is, so that an error about it
reads ``file:line: key`` (a syntax error ``file:line:``) and an editor can jump to it: device
profiles' errors (:mod:`opspec.bindings.profile_lines`), and the syntax error of the user model
``opspec validate`` checks beside a spec (:mod:`opspec.commands.validate_side_files`).

tomllib keeps no positions, so the text is scanned for table headers and ``key =`` lines.
A key written inside an inline table (``emulate = { reply = … }``) or never written (a
required key that is missing) is placed at the nearest enclosing key or table that is.
"""

from __future__ import annotations

import re

__all__ = ["key_line", "syntax_line"]

#: where tomllib says a syntax error is: "… (at line 14, column 18)"
_SYNTAX_AT = re.compile(r"\(at line (\d+), column \d+\)")

_HEADER = re.compile(r"^\s*\[\[?\s*(?P<path>[^\[\]]+?)\s*\]\]?\s*(#.*)?$")
_BARE = re.compile(r"[A-Za-z0-9_-]+")


def syntax_line(message: str) -> int | None:
    """The line tomllib's syntax error ``message`` names, or None."""
    found = _SYNTAX_AT.search(message)
    return int(found.group(1)) if found is not None else None


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
