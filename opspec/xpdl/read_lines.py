"""The exact line of every element, also past line 65,534.

libxml2 stores an element's line number in 16 bits: up to 65,534 lxml's ``sourceline`` is
exact, from 65,535 on it is a guess. For a longer file a second, counting-only pass over the
bytes (or expat, for encodings whose bytes cannot be scanned) finds the lines of the elements
past that point (:func:`big_lines`); inside :func:`exact_lines` :func:`line_of` looks them up,
and :func:`copy_line` gives an element made while normalising the line of the one it came from.
"""

from __future__ import annotations

import bisect
import itertools
import re
import xml.parsers.expat
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Final, Protocol

from lxml import etree

from opspec.xpdl.read_encoding import ASCII_NAMES, declared_encoding

__all__ = ["big_lines", "copy_line", "exact_lines", "line_of"]

# Past it lxml's ``sourceline`` is a guess: libxml2's XML_PARSE_BIG_LINES borrows the line of a
# neighbouring text node, which is where that text *ends*.
_LAST_TRUSTED_LINE: Final = 65534


class _WithLines(Protocol):
    """A parsed file (:class:`~opspec.xpdl.reader.ReadOutcome`,
    :class:`~opspec.xpdl.safe_xml.ParsedXml`): its elements' exact lines past 65,534."""

    @property
    def lines(self) -> Mapping[etree._Element, int]: ...


# The exact lines of the tree being built (set by :func:`exact_lines`; one per context, so
# threads and nested loads do not mix them up).
_EXACT: ContextVar[dict[etree._Element, int] | None] = ContextVar("opspec_exact_lines",
                                                                  default=None)


@contextmanager
def exact_lines(outcome: _WithLines) -> Iterator[None]:
    """Within this block, :func:`line_of` gives the exact line of the elements of
    ``outcome`` that lie past line 65,534 (and of elements :func:`copy_line` gave a line)."""
    token = _EXACT.set(dict(outcome.lines))
    try:
        yield
    finally:
        _EXACT.reset(token)


def line_of(element: object) -> int | None:
    """The 1-based line of an lxml element, or ``None`` when unknown or untrustworthy.

    Lines up to 65,534 come from libxml2; later ones from the reader's own count, inside
    :func:`exact_lines` (outside it they are ``None``: libxml2 only guesses them)."""
    line = getattr(element, "sourceline", None)
    if isinstance(line, int) and 0 < line <= _LAST_TRUSTED_LINE:
        return line
    exact = _EXACT.get()
    if exact is not None and line is not None:
        return exact.get(element)  # type: ignore[call-overload, unused-ignore]
    return None


def copy_line(source: etree._Element, target: etree._Element) -> None:
    """Give ``target`` (an element made while normalising) the line of ``source``."""
    line = line_of(source)
    if line is None:
        return
    if line <= _LAST_TRUSTED_LINE:
        target.sourceline = line
        return
    exact = _EXACT.get()
    if exact is not None:
        target.sourceline = 65535          # past libxml2's range: look it up
        exact[target] = line


# The rest of a start tag after its "<": what lies outside quotes, then the closing ">".
_START_TAG_REST = re.compile(rb"""(?:[^>"']+|"[^"]*"|'[^']*')*>""")
# Elements starting this many lines before the last trusted one are looked up too (a start tag
# spanning lines can begin below it and end past it).
_MARGIN: Final = 1000


# Markup in a byte-compatible encoding: comments, CDATA sections and processing instructions
# (skipped whole, as their text may hold "<"), end tags (not matched), and start tags up to
# their closing ">" (quoted attribute values may hold ">"; no value may hold "<").
_MARKUP = re.compile(rb"""<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|<(?!/)((?:[^>"']+|"[^"]*"|'[^']*')*)>""",
                     re.DOTALL)
# Encodings in which every "<", ">", quote and newline byte is that character (no other
# character's bytes contain them), so the lines can be counted in the bytes.
_BYTE_COMPATIBLE = frozenset({"utf-8", "utf8", *ASCII_NAMES, "iso-8859-1", "latin-1", "latin1",
                              "iso-8859-15", "windows-1252", "cp1252"})


_SPECIAL = re.compile(rb"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>", re.DOTALL)


def _byte_scan_lines(data: bytes, first_line: int) -> tuple[int, list[int]] | None:
    """With a scan of the bytes (about twice as fast as expat with a Python callback per
    element): how many elements start on or before ``first_line``, and the line of the closing
    ``>`` of each start tag after them, in document order.

    Before that line the start tags are only counted, in C: every "<" outside comments, CDATA
    sections and processing instructions opens a start or an end tag (no text or attribute
    value holds one)."""
    cut = 0
    for _ in range(first_line):       # the offset at which line first_line + 1 starts
        cut = data.find(b"\n", cut) + 1
        if cut == 0:
            return None
    start = cut                       # where the tag-by-tag scan begins
    specials: list[tuple[int, int]] = []
    for match in _SPECIAL.finditer(data):
        if match.start() >= cut:
            break
        if match.end() > cut:         # the cut is inside it: scan from its start
            start = match.start()
            break
        specials.append(match.span())
    if start == cut:
        # the cut inside a tag (not inside a special: no "<" after the last one's end)?
        at = data.rfind(b"<", 0, cut)
        if at >= 0 and (not specials or at >= specials[-1][1]):
            if data.startswith(b"</", at):
                end = data.find(b">", at) + 1
            else:
                rest = _START_TAG_REST.match(data, at + 1)
                end = rest.end() if rest is not None else 0
            if end > cut or end <= 0:
                start = at
    opened = data.count(b"<", 0, start) - data.count(b"</", 0, start)
    for begin, end in specials:
        if end <= start:
            opened -= data.count(b"<", begin, end) - data.count(b"</", begin, end)
    ends = [m.end() for m in _MARKUP.finditer(data, start) if m.start(1) >= 0]
    first = 0
    # a start tag beginning before the cut but ending after it began on line <= first_line
    while first < len(ends) and data.rfind(b"<", 0, ends[first]) < cut:
        first += 1
    lines: list[int] = []
    at = ends[first] if first < len(ends) else 0
    line = 1 + data.count(b"\n", 0, at)
    for end in itertools.islice(ends, first, None):
        line += data.count(b"\n", at, end)
        at = end
        lines.append(line)
    return opened + first, lines


def _expat_lines(data: bytes, encoding: str | None, first_line: int
                 ) -> tuple[int, list[int]] | None:
    """As :func:`_byte_scan_lines`, by a counting-only expat parse (any encoding expat
    reads; in UTF-16 the line is that of the start tag's ``<``)."""
    from array import array

    starts = array("q")
    offsets = array("q")
    parser = xml.parsers.expat.ParserCreate(encoding)

    def start(_name: str, _attributes: object) -> None:
        starts.append(parser.CurrentLineNumber)
        offsets.append(parser.CurrentByteIndex)

    parser.StartElementHandler = start
    try:
        parser.Parse(data, True)
    except (xml.parsers.expat.ExpatError, ValueError, LookupError, UnicodeError):
        return None
    byte_lines = not data.startswith((b"\xff\xfe", b"\xfe\xff", b"\x00<", b"<\x00"))
    first = bisect.bisect_right(starts, first_line)
    lines: list[int] = []
    for index in range(first, len(starts)):
        line = starts[index]
        if byte_lines:
            at = offsets[index]
            end = _START_TAG_REST.match(data, at + 1)
            if end is not None:
                line += data.count(b"\n", at, end.end())
        lines.append(line)
    return first, lines


def big_lines(data: bytes, root: etree._Element, encoding: str | None
               ) -> dict[etree._Element, int]:
    """The exact line of every element past libxml2's 16-bit line numbers, found by a second,
    counting-only pass (a scan of the bytes, or expat for encodings whose bytes cannot be
    scanned) paired with the tree in document order; empty for short files, or when the two
    do not see the same elements (then such lines are unknown, as libxml2 leaves them).

    The line given is that of the start tag's closing ``>``, as libxml2 gives below 65,535."""
    if data.count(b"\n") < _LAST_TRUSTED_LINE:
        return {}
    declared = encoding or declared_encoding(data) or "utf-8"
    if declared in _BYTE_COMPATIBLE and not data.startswith((b"\xff\xfe", b"\xfe\xff")):
        found = _byte_scan_lines(data, _LAST_TRUSTED_LINE - _MARGIN)
    else:
        found = _expat_lines(data, encoding, _LAST_TRUSTED_LINE - _MARGIN)
    if found is None:
        return {}
    first, lines = found
    elements = root.iter(etree.Element)
    skipped = sum(1 for _ in itertools.islice(elements, first))
    if skipped != first:
        return {}
    exact = {element: line for line, element in zip(lines, elements)}
    if len(exact) != len(lines) or next(elements, None) is not None:
        return {}
    return exact
