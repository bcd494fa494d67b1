"""Which encoding a specification file is in: the one its XML declaration names, ``ASCII``
declarations on files that really hold UTF-8 (read as UTF-8, which loses nothing), the
warning given when a file that is not valid UTF-8 and declares nothing else is read as
Latin-1 (at the line of the first byte that is not UTF-8, naming that byte's value), and the
refusal of a declaration the file cannot be in (no such encoding; UTF-16 or UTF-32 declared in
8-bit text).
"""

from __future__ import annotations

import codecs
import re
from typing import Final

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation

__all__ = ["ASCII_NAMES", "declared_encoding", "encoding_warning", "impossible_declaration",
           "is_encoding_error"]

_DECLARED_ENCODING = re.compile(rb"""^\s*<\?xml[^>]*?encoding\s*=\s*["']([A-Za-z0-9._-]+)["']""")
ASCII_NAMES: Final = frozenset({"ascii", "us-ascii", "ansi_x3.4-1968", "iso646-us", "us"})


def declared_encoding(data: bytes) -> str | None:
    match = _DECLARED_ENCODING.match(data.removeprefix(b"\xef\xbb\xbf")[:512])
    return match.group(1).decode("ascii").lower() if match else None


def impossible_declaration(declared: str | None, error: etree.XMLSyntaxError
                           ) -> tuple[str, str] | None:
    """(message, hint) when a file libxml2 could not read declares an encoding it cannot be
    in: one no codec knows ('bogus-8'), or a 16- or 32-bit one while the declaration itself
    is 8-bit text (as :func:`declared_encoding` finds it). libxml2 says "Unsupported
    encoding" or, decoding 8-bit bytes as UTF-16, "Blank needed here" at the declaration's
    end: neither is an XML syntax error to fix at that line."""
    if declared is None:
        return None
    hint = ("make the XML declaration name the encoding the file is saved in "
            "(encoding=\"UTF-8\" when unsure)")
    try:
        codecs.lookup(declared)
    except LookupError:
        if is_encoding_error(error):
            return ((f"the XML declaration names encoding {declared!r}, which is no "
                     "encoding opspec knows, so the file cannot be read"), hint)
        return None
    if declared.replace("-", "").startswith(("utf16", "utf32", "ucs2", "ucs4")):
        return ((f"the XML declaration says {declared.upper()}, but the file is 8-bit text "
                 f"(the declaration itself is), so it cannot be {declared.upper()} and cannot "
                 "be read"), hint)
    return None


def is_encoding_error(error: etree.XMLSyntaxError) -> bool:
    text = str(error).lower()
    return "encoding" in text or "utf-8" in text or "char 0x" in text


def _first_bad_utf8(data: bytes) -> tuple[int, int] | None:
    """The 1-based line and the value of the first byte that is not valid UTF-8."""
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as error:
        return data.count(b"\n", 0, error.start) + 1, data[error.start]
    return None


def encoding_warning(data: bytes, path: str, declared: str | None, line: int | None
                     ) -> Diagnostic:
    bad = _first_bad_utf8(data)
    # the diagnostic's file:line is the byte's line: the message names the byte alone
    where = f" (byte 0x{bad[1]:02X})" if bad else ""
    if bad:
        line = bad[0]
    if declared == "utf-8":
        message = (f"the file declares UTF-8 but is not valid UTF-8{where}; read it as Latin-1")
        hint = ("save the file as UTF-8, or make its XML declaration name the encoding it "
                "really uses (e.g. encoding=\"ISO-8859-1\")")
    elif declared in ASCII_NAMES:
        message = (f"the file declares {declared.upper()} but holds bytes that are neither "
                   f"ASCII nor UTF-8{where}; read it as Latin-1")
        hint = "add an XML declaration naming the real encoding, or save the file as UTF-8"
    else:
        message = (f"the file is not valid UTF-8{where} and declares no other encoding; "
                   "read it as Latin-1")
        hint = "add an XML declaration naming the real encoding, or save the file as UTF-8"
    return Diagnostic(SourceLocation(path, line), Severity.WARNING, "encoding-guessed",
                      message, hint)
