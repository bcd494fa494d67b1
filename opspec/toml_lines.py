"""Where in a TOML file people write a key or a syntax error is, so that an error about it
reads ``file:line: key`` (a syntax error ``file:line:``) and an editor can jump to it: device
profiles' errors (:mod:`opspec.bindings.profile_lines`), user models and populations
(:mod:`opspec.usermodels.loader`), world files (:mod:`opspec.worlds`), the engine
configuration (:mod:`opspec.engine.config`) and any TOML syntax error
(:mod:`opspec.toml_files`).

tomllib keeps no positions, so the text is scanned here: table headers (``[a.b]``, arrays of
tables ``[[a]]``, whose entries are named ``a[0]``, ``a[1]``…), ``key = value`` lines with
dotted and quoted keys, inline tables (``d = { kind = "x", median = 3 }``: ``d.median``) and
arrays, multi-line ones too (``obstacles = [`` … one entry a line: ``obstacles[1]``), with
strings (multi-line ones too) and comments skipped. A key never written (a required key that
is missing) is placed at the nearest enclosing key or table that is.
"""

from __future__ import annotations

import re
from pathlib import Path

from opspec.errors import SourceLocation

__all__ = ["key_line", "located", "syntax_line"]

#: where tomllib says a syntax error is: "… (at line 14, column 18)"
_SYNTAX_AT = re.compile(r"\(at line (\d+), column \d+\)")
_BARE = re.compile(r"[A-Za-z0-9_-]+")
#: larger files are not scanned for a line (no TOML file people write comes near it)
_MAX_SCANNED = 4 * 1024 * 1024


def syntax_line(message: str) -> int | None:
    """The line tomllib's syntax error ``message`` names, or None."""
    found = _SYNTAX_AT.search(message)
    return int(found.group(1)) if found is not None else None


def key_line(text: str, key: str) -> int | None:
    """The 1-based line where ``key`` (dotted, parts unquoted, entries of arrays as
    ``windows[0]``: as the loaders name it) or its nearest written parent is defined in the
    TOML ``text``; None when neither is (a key of the top table that is missing)."""
    best: tuple[int, int] | None = None        # (length of the matched path, line)
    for path, line in _Scanner(text).paths().items():
        if ((key == path or key.startswith((path + ".", path + "[")))
                and (best is None or len(path) > best[0])):
            best = (len(path), line)
    return None if best is None else best[1]


def located(path: str, key: str | None, text: str | None = None) -> SourceLocation:
    """Where ``key`` of the TOML file ``path`` is: ``path``, the line of the key (or of its
    nearest written parent) and the key. ``text`` is the file's text when the caller has
    it; otherwise the file is read now (no line when it cannot be: an error about a document
    that came from no file keeps ``path: key``)."""
    if not key:
        return SourceLocation(path)
    if text is None:
        text = _text_of(path)
    return SourceLocation(path, None if text is None else key_line(text, key), key)


def _text_of(path: str) -> str | None:
    """The text of the regular file ``path``, or None (not a file, unreadable, not UTF-8,
    too large to scan)."""
    try:
        file = Path(path)
        if not file.is_file() or file.stat().st_size > _MAX_SCANNED:
            return None                     # a pipe or device is never opened
        return file.read_text(encoding="utf-8-sig")     # as the file was read
    except (OSError, UnicodeDecodeError, ValueError):
        return None


class _Scanner:
    """Every table and key path a TOML text writes, with the first line writing it. It never
    raises: text that is not TOML is skipped a line at a time."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.at = 0
        self.line = 1
        self.found: dict[str, int] = {}
        self.tables: dict[str, int] = {}    # array of tables ([[a]]) -> entries so far

    def paths(self) -> dict[str, int]:
        table: list[str] = []
        while True:
            self._blank(newlines=True)
            if self.at >= len(self.text):
                return self.found
            start, line = self.at, self.line
            if self._char() == "[":
                table = self._header(line) or table
            else:
                parts = self._key()
                self._blank()
                if parts is not None and self._char() == "=":
                    self.at += 1
                    self._value(self._define(table, parts, line))
            if self.at == start or self._char() not in ("\n", "\r", "#", " ", "\t", ""):
                self._skip_line()           # not TOML this scanner knows: on to the next line

    # --- structure -------------------------------------------------------------------

    def _header(self, line: int) -> list[str] | None:
        """``[a.b]`` or ``[[a.b]]``: the table's path, entries of arrays of tables indexed."""
        array = self.text.startswith("[[", self.at)
        self.at += 2 if array else 1
        parts = self._key()
        self._blank()
        closing = "]]" if array else "]"
        if parts is None or not self.text.startswith(closing, self.at):
            self._skip_line()
            return None
        self.at += len(closing)
        path: list[str] = []
        for number, part in enumerate(parts):
            name = ".".join([*path, part])
            if number == len(parts) - 1 and array:
                index = self.tables.get(name, 0)
                self.tables[name] = index + 1
                self.found.setdefault(name, line)
                part = f"{part}[{index}]"
            elif name in self.tables:       # [[a]] then [a.b]: b of a's last entry
                self.found.setdefault(name, line)
                part = f"{part}[{self.tables[name] - 1}]"
            path.append(part)
            self.found.setdefault(".".join(path), line)
        return path

    def _define(self, table: list[str], parts: list[str], line: int) -> str:
        full = [*table, *parts]
        for end in range(len(table) + 1, len(full) + 1):
            self.found.setdefault(".".join(full[:end]), line)
        return ".".join(full)

    def _value(self, path: str) -> None:
        self._blank()
        char = self._char()
        if char in ('"', "'"):
            self._string()
        elif char == "[":
            self._array(path)
        elif char == "{":
            self._inline_table(path)
        else:                               # a number, date, boolean: up to what ends it
            while self._char() not in (",", "]", "}", "\n", "\r", "#", ""):
                self.at += 1

    def _array(self, path: str) -> None:
        self.at += 1
        index = 0
        while True:
            self._blank(newlines=True)
            if self._char() in ("]", ""):
                self.at += 1
                return
            entry = f"{path}[{index}]"
            self.found.setdefault(entry, self.line)
            start = self.at
            self._value(entry)
            index += 1
            self._blank(newlines=True)
            if self._char() == ",":
                self.at += 1
            elif self._char() == "]" or self.at == start:
                self.at += 1
                return

    def _inline_table(self, path: str) -> None:
        self.at += 1
        while True:
            self._blank(newlines=True)
            if self._char() in ("}", ""):
                self.at += 1
                return
            line = self.line
            parts = self._key()
            self._blank()
            if parts is None or self._char() != "=":
                return
            self.at += 1
            self._value(self._define(path.split("."), parts, line))
            self._blank(newlines=True)
            if self._char() == ",":
                self.at += 1

    # --- tokens ----------------------------------------------------------------------

    def _key(self) -> list[str] | None:
        """The parts of a dotted key (bare or quoted), or None if none is here."""
        parts: list[str] = []
        while True:
            self._blank()
            char = self._char()
            if char in ('"', "'"):
                start = self.at + 1
                self._string()
                parts.append(self._unescaped(self.text[start:self.at - 1], char))
            else:
                bare = _BARE.match(self.text, self.at)
                if bare is None:
                    return None
                parts.append(bare.group())
                self.at = bare.end()
            self._blank()
            if self._char() != ".":
                return parts
            self.at += 1

    @staticmethod
    def _unescaped(raw: str, quote: str) -> str:
        if quote == "'":
            return raw
        return re.sub(r"\\(.)", r"\1", raw)     # \" and \\ as written in keys

    def _string(self) -> None:
        """Past a string starting here: basic, literal, or either multi-line."""
        quote = self._char()
        if self.text.startswith(quote * 3, self.at):
            self.at += 3
            while self.at < len(self.text):
                if self.text.startswith(quote * 3, self.at):
                    self.at += 3
                    while self._char() == quote:    # up to two quotes end the content
                        self.at += 1
                    return
                if quote == '"' and self._char() == "\\":
                    self._step()
                self._step()
            return
        self.at += 1
        while self._char() not in (quote, "\n", ""):
            if quote == '"' and self._char() == "\\":
                self.at += 1
            if self._char() != "\n":
                self.at += 1
        if self._char() == quote:
            self.at += 1

    def _blank(self, *, newlines: bool = False) -> None:
        """Past spaces and comments (and line ends, when ``newlines``)."""
        while self.at < len(self.text):
            char = self.text[self.at]
            if char in " \t":
                self.at += 1
            elif char == "#":
                while self._char() not in ("\n", ""):
                    self.at += 1
            elif newlines and char in "\r\n":
                self._step()
            else:
                return

    def _skip_line(self) -> None:
        while self._char() not in ("\n", ""):
            self.at += 1
        self._step()

    def _step(self) -> None:
        if self.at < len(self.text):
            if self.text[self.at] == "\n":
                self.line += 1
            self.at += 1

    def _char(self) -> str:
        return self.text[self.at] if self.at < len(self.text) else ""
