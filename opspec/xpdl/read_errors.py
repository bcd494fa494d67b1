"""The reader's fatal errors: :class:`XmlReadError` (a :class:`~opspec.errors.SpecError` with
a stable ``code`` and the file:line where the problem was found), and what the parse failures
say: a DOCTYPE refused, XML that is not well-formed (libxml2's message with its position
said once: the line in the diagnostic's file:line, the column in words; a file that ends
before its XML is complete said so, at its last line), or a well-formed file beyond one of
libxml2's safety limits (with advice for the spec's author, not "fix the syntax").
"""

from __future__ import annotations

import re
from typing import Final

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation, SpecError

__all__ = ["XmlReadError", "doctype_error", "not_well_formed_error"]


class XmlReadError(SpecError):
    """A file cannot be read as XPDL at all. ``code`` is one of ``io-error``, ``too-big``,
    ``empty-file``, ``not-well-formed``, ``resource-limit``, ``doctype``, ``unknown-root``,
    ``unknown-version``, ``compiled-script``, ``not-a-spec``, ``bad-setting``."""

    def __init__(self, code: str, message: str, *, location: SourceLocation, hint: str = "") -> None:
        self.code = code
        super().__init__(message, location=location, hint=hint)

    def diagnostic(self) -> Diagnostic:
        location = self.location or SourceLocation("<unknown>")
        return Diagnostic(location, Severity.ERROR, self.code, self.message, self.hint)


def doctype_error(path: str, line: int | None) -> XmlReadError:
    return XmlReadError(
        "doctype",
        "DOCTYPE declarations are not allowed in specifications",
        location=SourceLocation(path, line),
        hint="remove the <!DOCTYPE ...> line; XPDL needs no DTD, and DTDs can read local files "
        "or expand entities without bound",
    )


# libxml2's safety limits (huge_tree=False) and what they mean for a spec's author: a
# well-formed file can hit them, so "fix the XML syntax" would be the wrong advice.
_LIMITS: Final = (
    (re.compile(r"excessive depth", re.IGNORECASE),
     "elements are nested more than 256 levels deep, the XML reader's limit",
     ("XPDL needs a few dozen levels at most: flatten the deeply nested content, often "
      "inside an ExtendedAttribute, or move it to a file of its own")),
    (re.compile(r"buffer size limit|text node too long|too long|huge text", re.IGNORECASE),
     "a text or attribute value is longer than the XML reader's limit of 10,000,000 characters",
     ("keep bulk data out of the spec: put it in a file of its own and refer to it; a value "
      "this long usually means a damaged or generated file")),
    (re.compile(r"resource limit|huge input|amplification|memory allocation", re.IGNORECASE),
     "the XML exceeds a resource limit of the XML reader",
     "simplify the file: no spec needs anything this large; is it damaged or generated?"),
)


# What libxml2 says only when the input stops inside something still open: the error is at
# the end of the file, where "fix the XML syntax at that line" points at nothing to fix (a
# line past the last, when the file ends with a newline), and the cure is the missing end.
_ENDS_EARLY: Final = (
    (re.compile(r"^Premature end of data in tag (\S+) line (\d+)"),
     "<{0}>, opened at line {1}, is not closed"),
    (re.compile(r"^Premature end of data"), "an element is not closed"),
    (re.compile(r"^EndTag: '</' not found"), "an element is not closed"),
    (re.compile(r"^Comment not terminated"), "a comment is not closed with -->"),
    (re.compile(r"^CData section not finished"), "a CDATA section is not closed with ]]>"),
    (re.compile(r"^ParsePI: PI .* never end"), "a processing instruction is not closed with ?>"),
)


def _one_line(text: str) -> str:
    return " ".join(text.split())


#: the position lxml appends to libxml2's message (", line 52, column 19"): the diagnostic's
#: file:line says the line already
_POSITION = re.compile(r",\s*line \d+,\s*column (\d+)$")

#: libxml2's "Foo line 47" (a tag and the line it was opened on) written as a tag; ``{at}``:
#: " of line 47", or nothing when that is the diagnostic's own line
_TAGS: Final = (
    (re.compile(r"^Opening and ending tag mismatch: (?P<tag>\S+) line (?P<line>\d+) "
                r"and (?P<end>\S+)$"),
     "Opening and ending tag mismatch: <{tag}>{at} and </{end}>"),
    (re.compile(r"^Couldn't find end of Start Tag (?P<tag>\S+) line (?P<line>\d+)$"),
     "Couldn't find the end of the start tag <{tag}>{at}"),
)


def _without_position(message: str, line: int | None) -> tuple[str, int | None]:
    """libxml2's ``message`` for an error the diagnostic places at ``line``, without the
    position lxml appends to it and with its tags written as tags; and the column that
    position named (``None``: it named none)."""
    found = _POSITION.search(message)
    column = int(found.group(1)) if found else None
    text = message[:found.start()].rstrip() if found else message
    for pattern, words in _TAGS:
        tag = pattern.search(text)
        if tag is not None:
            opened = int(tag["line"])
            at = "" if opened == line else f" of line {opened}"
            return words.format(at=at, **tag.groupdict()), column
    return text, column


#: libxml2's messages for a tag it could not finish: at the end of the file, the file ends
#: inside it (a mismatched end tag at the end is a real syntax error, not a cut)
_NEEDS_MORE = re.compile(r"expected '>'|Couldn't find end of Start Tag|AttValue|"
                         r"attributes construct error|mandates value for attribute")

_CUT_SHORT = ("the file may have been cut short: restore its end (from a copy, or from the "
              "tool that wrote it)")


def _ends_early(path: str, message: str, error: etree.XMLSyntaxError,
                end: tuple[int, int] | None) -> XmlReadError | None:
    """The error for a file that stops before its XML is complete, at its last line, or
    None when ``message`` is not one libxml2 gives at the end of the input: something still
    open (:data:`_ENDS_EARLY`), or a tag it could not finish placed at or past ``end`` (the
    file's last line and its width)."""
    for pattern, what in _ENDS_EARLY:
        found = pattern.search(message)
        if found is None:
            continue
        line = error.lineno or None
        if line is not None and line > 1 and not error.offset:
            line -= 1       # column 1 of the line after the file's final newline: no such line
        return XmlReadError(
            "not-well-formed",
            f"the file ends before the XML is complete ({what.format(*found.groups())})",
            location=SourceLocation(path, line), hint=_CUT_SHORT)
    line, column = error.lineno or 0, error.offset or 0
    if (end is not None and _NEEDS_MORE.search(message)
            and (line > end[0] or line == end[0] and column >= end[1])):
        # libxml2 reads on past the end for the '>' or quote it still needs; its own
        # position (a line after the last) is left out of the message
        what, _past_the_end = _without_position(message, end[0])
        return XmlReadError(
            "not-well-formed",
            f"the file ends inside a tag, before the XML is complete ({what})",
            location=SourceLocation(path, end[0]), hint=_CUT_SHORT)
    return None


def not_well_formed_error(path: str, error: etree.XMLSyntaxError,
                          end: tuple[int, int] | None = None) -> XmlReadError:
    """The error for XML libxml2 cannot read; ``end``: the file's last line and its width
    (an error placed past them is the file ending inside a tag)."""
    message = error.msg or str(error)
    message = re.sub(r"\s*\(<string>, line \d+\)$", "", message)
    for pattern, what, hint in _LIMITS:
        if pattern.search(message):
            return XmlReadError("resource-limit", what,
                                location=SourceLocation(path, error.lineno or None), hint=hint)
    message = _one_line(message)
    early = _ends_early(path, message, error, end)
    if early is not None:
        return early
    line = error.lineno or None
    what, column = _without_position(message, line)
    return XmlReadError(
        "not-well-formed",
        f"not well-formed XML at column {column}: {what}" if column else
        f"not well-formed XML: {what}",
        location=SourceLocation(path, line),
        hint="fix the XML syntax at that line (an editor with XML checking shows it)",
    )
