"""The hardened XML reader: bytes in, an lxml tree and its XPDL version out.

Contract:

- no network, no DTD loading, no entity expansion (``XMLParser(resolve_entities=False,
  no_network=True, load_dtd=False, huge_tree=False)``), and any ``DOCTYPE`` is rejected outright
  (XPDL never needs one; DTDs are how XXE and entity bombs get in);
- a size limit (:data:`DEFAULT_MAX_BYTES`; callers pass ``max_bytes``, users set the
  environment variable :data:`MAX_BYTES_VARIABLE`, which replaces the default) checked before
  parsing, and while reading a stream, so a 1 GB file is never read into memory;
- byte-order marks (UTF-8/UTF-16), missing XML declarations and ``ASCII``/``us-ascii``
  declarations on files that really hold UTF-8 are handled; a file that is not valid UTF-8 and
  declares nothing else is read as Latin-1 with a warning;
- the version comes from the root element's namespace only (:mod:`opspec.xpdl.namespaces`);
- every fatal problem is an :class:`XmlReadError` (a :class:`~opspec.errors.SpecError`) with a
  stable ``code`` and the file:line where it was found.
"""

from __future__ import annotations

import bisect
import itertools
import os
import re
import xml.parsers.expat
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO, Final

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation, SpecError
from opspec.files import NotARegularFile, not_a_file, open_regular
from opspec.model.package import XpdlVersion
from opspec.xpdl.namespaces import XPDL_NAMESPACES, version_of_namespace

__all__ = [
    "DEFAULT_MAX_BYTES",
    "MAX_BYTES_VARIABLE",
    "ParsedXml",
    "ReadOutcome",
    "XmlReadError",
    "copy_line",
    "effective_max_bytes",
    "exact_lines",
    "line_of",
    "not_a_file",
    "parse_safely",
    "read_file",
    "read_limited",
    "read_tree",
    "read_xml",
    "xpdl_outcome",
]

#: Default size limit of one specification file (64 MiB).
DEFAULT_MAX_BYTES: Final = 64 * 1024 * 1024
#: The environment variable that sets the size limit in bytes instead of the default
#: (``OPSPEC_MAX_SPEC_BYTES=200000000 opspec validate big.xpdl``; docs/validation.md).
MAX_BYTES_VARIABLE: Final = "OPSPEC_MAX_SPEC_BYTES"

# libxml2 stores an element's line number in 16 bits: from 65,535 on, lxml's ``sourceline`` is
# a guess (libxml2's XML_PARSE_BIG_LINES borrows the line of a neighbouring text node, which is
# where that text *ends*). The reader finds the exact lines of such elements itself (see
# :func:`_big_lines`) and :func:`line_of` looks them up.
_LAST_TRUSTED_LINE: Final = 65534
_CHUNK: Final = 1024 * 1024

_DECLARED_ENCODING = re.compile(rb"""^\s*<\?xml[^>]*?encoding\s*=\s*["']([A-Za-z0-9._-]+)["']""")
_ASCII_NAMES: Final = frozenset({"ascii", "us-ascii", "ansi_x3.4-1968", "iso646-us", "us"})
_DOCTYPE_MARKERS: Final = (
    b"<!DOCTYPE",
    "<!DOCTYPE".encode("utf-16-le"),
    "<!DOCTYPE".encode("utf-16-be"),
)


class XmlReadError(SpecError):
    """A file cannot be read as XPDL at all. ``code`` is one of ``io-error``, ``too-big``,
    ``empty-file``, ``not-well-formed``, ``resource-limit``, ``doctype``, ``unknown-root``,
    ``unknown-version``, ``compiled-script``, ``bad-setting``."""

    def __init__(self, code: str, message: str, *, location: SourceLocation, hint: str = "") -> None:
        self.code = code
        super().__init__(message, location=location, hint=hint)

    def diagnostic(self) -> Diagnostic:
        location = self.location or SourceLocation("<unknown>")
        return Diagnostic(location, Severity.ERROR, self.code, self.message, self.hint)


@dataclass(frozen=True, slots=True)
class ReadOutcome:
    """A parsed file: its root element, its version and non-fatal reading warnings.

    ``lines`` holds the exact line of every element past line 65,534 (empty for shorter
    files); :func:`line_of` consults it inside :func:`exact_lines`."""

    root: etree._Element
    version: XpdlVersion
    warnings: tuple[Diagnostic, ...] = ()
    lines: Mapping[etree._Element, int] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class ParsedXml:
    """A file parsed safely, before anyone looked at what its root element is (XPDL
    ``Package``, BPMN ``definitions``): the root, reading warnings and the exact lines past
    65,534 (as in :class:`ReadOutcome`)."""

    root: etree._Element
    warnings: tuple[Diagnostic, ...] = ()
    lines: Mapping[etree._Element, int] = field(default_factory=dict)


# The exact lines of the tree being built (set by :func:`exact_lines`; one per context, so
# threads and nested loads do not mix them up).
_EXACT: ContextVar[dict[etree._Element, int] | None] = ContextVar("opspec_exact_lines",
                                                                  default=None)


@contextmanager
def exact_lines(outcome: ReadOutcome | ParsedXml) -> Iterator[None]:
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


def _parser(encoding: str | None = None) -> etree.XMLParser:
    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=False,
        encoding=encoding,
    )


def effective_max_bytes(max_bytes: int, *, path: str = "<spec>") -> int:
    """``max_bytes``, or the value of :data:`MAX_BYTES_VARIABLE` when the caller left the
    default. A value that is not a positive whole number is an :class:`XmlReadError`
    (``bad-setting``) rather than silently ignored."""
    raw = os.environ.get(MAX_BYTES_VARIABLE, "").strip()
    if max_bytes != DEFAULT_MAX_BYTES or not raw:
        return max_bytes
    try:
        value = int(raw.replace("_", ""))
    except ValueError:
        value = 0
    if value <= 0:
        raise XmlReadError(
            "bad-setting",
            f"{MAX_BYTES_VARIABLE}={raw!r} is not a positive whole number of bytes",
            location=SourceLocation(path, 1),
            hint=f"set e.g. {MAX_BYTES_VARIABLE}=200000000, or unset it for the default "
            f"of {DEFAULT_MAX_BYTES:,} bytes")
    return value


def read_limited(stream: BinaryIO, *, path: str, max_bytes: int = DEFAULT_MAX_BYTES) -> bytes:
    """Read a binary stream to its end, refusing it as soon as it exceeds ``max_bytes``
    (see :func:`effective_max_bytes`).

    At most ``max_bytes`` plus one chunk is ever held in memory.
    """
    max_bytes = effective_max_bytes(max_bytes, path=path)
    chunks: list[bytes] = []
    total = 0
    while True:
        chunk = stream.read(min(_CHUNK, max_bytes + 1 - total) or 1)
        if not chunk:
            return b"".join(chunks)
        total += len(chunk)
        if total > max_bytes:
            raise _too_big(path, max_bytes)
        chunks.append(chunk)


def read_file(path: str | Path, *, max_bytes: int = DEFAULT_MAX_BYTES) -> bytes:
    """The bytes of a regular file, checking its size before reading it. Folders, pipes,
    devices and sockets are refused (``io-error``) without blocking."""
    shown = str(path)
    max_bytes = effective_max_bytes(max_bytes, path=shown)
    try:
        with open_regular(path) as stream:
            size = os.fstat(stream.fileno()).st_size
            if size > max_bytes:
                raise _too_big(shown, max_bytes)
            return read_limited(stream, path=shown, max_bytes=max_bytes)
    except XmlReadError:
        raise
    except (NotARegularFile, FileNotFoundError) as error:
        why = "it does not exist" if isinstance(error, FileNotFoundError) else error.strerror
        raise XmlReadError(
            "io-error",
            f"cannot read the file: {why}",
            location=SourceLocation(shown),
            hint="give the path of an XPDL file; specs are not read from folders, pipes or "
            "devices",
        ) from None
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise XmlReadError(
            "io-error",
            f"cannot read the file: {reason}",
            location=SourceLocation(shown),
            hint="check the path and its permissions",
        ) from None


def _too_big(path: str, max_bytes: int) -> XmlReadError:
    # Line 1: the file as a whole is refused, before any of it is parsed.
    return XmlReadError(
        "too-big",
        f"the file is larger than the limit of {max_bytes:,} bytes, so it was not read",
        location=SourceLocation(path, 1),
        hint="split the package into several files referenced as ExternalPackages, or raise "
        f"raise the limit: set the environment variable {MAX_BYTES_VARIABLE} to a number of "
        "bytes",
    )


def _is_compiled_script(data: bytes) -> bool:
    """True for the JSON of an ``opspec compile`` output (docs/wfs-format.md)."""
    head = data[:512].lstrip()
    return head.startswith(b"{") and b'"opspec-wfs"' in head


def _has_doctype(data: bytes) -> bool:
    head = data[: 64 * 1024]
    return any(marker in head for marker in _DOCTYPE_MARKERS)


def _doctype_line(data: bytes) -> int | None:
    """The 1-based line of the first ``<!DOCTYPE`` in ``data`` (UTF-8 or UTF-16); a DOCTYPE
    comes before the root element, so the first one is the real one."""
    head = data
    for marker, newline in zip(_DOCTYPE_MARKERS,
                               (b"\n", "\n".encode("utf-16-le"), "\n".encode("utf-16-be")),
                               strict=True):
        at = head.find(marker)
        if at >= 0:
            return head.count(newline, 0, at) + 1
    return None


def _doctype_error(path: str, line: int | None) -> XmlReadError:
    return XmlReadError(
        "doctype",
        "DOCTYPE declarations are not allowed in specifications",
        location=SourceLocation(path, line),
        hint="remove the <!DOCTYPE ...> line; XPDL needs no DTD, and DTDs can read local files "
        "or expand entities without bound",
    )


def _declared_encoding(data: bytes) -> str | None:
    match = _DECLARED_ENCODING.match(data.removeprefix(b"\xef\xbb\xbf")[:512])
    return match.group(1).decode("ascii").lower() if match else None


def _is_encoding_error(error: etree.XMLSyntaxError) -> bool:
    text = str(error).lower()
    return "encoding" in text or "utf-8" in text or "char 0x" in text


def _first_bad_utf8(data: bytes) -> tuple[int, int] | None:
    """The 1-based line and the value of the first byte that is not valid UTF-8."""
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as error:
        return data.count(b"\n", 0, error.start) + 1, data[error.start]
    return None


def _encoding_warning(data: bytes, path: str, declared: str | None, line: int | None
                      ) -> Diagnostic:
    bad = _first_bad_utf8(data)
    where = f" (line {bad[0]}: byte 0x{bad[1]:02X})" if bad else ""
    if bad:
        line = bad[0]
    if declared == "utf-8":
        message = (f"the file declares UTF-8 but is not valid UTF-8{where}; read it as Latin-1")
        hint = ("save the file as UTF-8, or make its XML declaration name the encoding it "
                "really uses (e.g. encoding=\"ISO-8859-1\")")
    elif declared in _ASCII_NAMES:
        message = (f"the file declares {declared.upper()} but holds bytes that are neither "
                   f"ASCII nor UTF-8{where}; read it as Latin-1")
        hint = "add an XML declaration naming the real encoding, or save the file as UTF-8"
    else:
        message = (f"the file is not valid UTF-8{where} and declares no other encoding; "
                   "read it as Latin-1")
        hint = "add an XML declaration naming the real encoding, or save the file as UTF-8"
    return Diagnostic(SourceLocation(path, line), Severity.WARNING, "encoding-guessed",
                      message, hint)


def _parse(data: bytes, path: str) -> tuple[etree._Element, list[Diagnostic], str | None]:
    """The root, the reading warnings, and the encoding the parser was told to use (``None``:
    the file's own)."""
    warnings: list[Diagnostic] = []
    declared = _declared_encoding(data)
    utf16 = data.startswith((b"\xff\xfe", b"\xfe\xff"))
    # Files that declare ASCII but hold UTF-8 (common in exported fragments): UTF-8 is a superset
    # of ASCII, so reading them as UTF-8 loses nothing and accepts the real content.
    first = "utf-8" if declared in _ASCII_NAMES else None
    try:
        return etree.fromstring(data, _parser(first)), warnings, first
    except etree.XMLSyntaxError as error:
        if _has_doctype(data):
            raise _doctype_error(path, _doctype_line(data) or error.lineno) from None
        retry = not utf16 and _is_encoding_error(error) and declared in (None, "utf-8", *_ASCII_NAMES)
        if not retry:
            raise _not_well_formed(path, error) from None
        original = error
    try:
        root = etree.fromstring(data, _parser("iso-8859-1"))
    except etree.XMLSyntaxError:
        raise _not_well_formed(path, original) from None
    warnings.append(_encoding_warning(data, path, declared, original.lineno or None))
    return root, warnings, "iso-8859-1"


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
_BYTE_COMPATIBLE = frozenset({"utf-8", "utf8", *_ASCII_NAMES, "iso-8859-1", "latin-1", "latin1",
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


def _big_lines(data: bytes, root: etree._Element, encoding: str | None
               ) -> dict[etree._Element, int]:
    """The exact line of every element past libxml2's 16-bit line numbers, found by a second,
    counting-only pass (a scan of the bytes, or expat for encodings whose bytes cannot be
    scanned) paired with the tree in document order; empty for short files, or when the two
    do not see the same elements (then such lines are unknown, as libxml2 leaves them).

    The line given is that of the start tag's closing ``>``, as libxml2 gives below 65,535."""
    if data.count(b"\n") < _LAST_TRUSTED_LINE:
        return {}
    declared = encoding or _declared_encoding(data) or "utf-8"
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


def _one_line(text: str) -> str:
    return " ".join(text.split())


def _not_well_formed(path: str, error: etree.XMLSyntaxError) -> XmlReadError:
    message = error.msg or str(error)
    message = re.sub(r"\s*\(<string>, line \d+\)$", "", message)
    for pattern, what, hint in _LIMITS:
        if pattern.search(message):
            return XmlReadError("resource-limit", what,
                                location=SourceLocation(path, error.lineno or None), hint=hint)
    message = _one_line(message)
    return XmlReadError(
        "not-well-formed",
        f"not well-formed XML: {message}",
        location=SourceLocation(path, error.lineno or None),
        hint="fix the XML syntax at that line (an editor with XML checking shows it)",
    )


def read_tree(data: bytes, *, path: str, max_bytes: int = DEFAULT_MAX_BYTES) -> ReadOutcome:
    """Parse ``data`` safely and check that it is an XPDL package. Raises :class:`XmlReadError`."""
    return xpdl_outcome(parse_safely(data, path=path, max_bytes=max_bytes), path=path)


def parse_safely(data: bytes, *, path: str, max_bytes: int = DEFAULT_MAX_BYTES) -> ParsedXml:
    """Parse ``data`` with every protection of this module (size, DOCTYPE, no entities, no
    network, encodings, exact lines), whatever its root element. Raises :class:`XmlReadError`.
    The BPMN reader (:mod:`opspec.xpdl.bpmn`) reads its files through here too."""
    max_bytes = effective_max_bytes(max_bytes, path=path)
    if len(data) > max_bytes:
        raise _too_big(path, max_bytes)
    if not data.strip(b" \t\r\n\x00\xef\xbb\xbf\xff\xfe"):
        raise XmlReadError(
            "empty-file",
            "the file is empty (no XML in it)",
            location=SourceLocation(path, 1),
            hint="an XPDL file starts with a <Package> element, a BPMN file with "
            "<bpmn:definitions>",
        )
    if _is_compiled_script(data):
        raise XmlReadError(
            "compiled-script",
            "this is a compiled workflow script (.wfs), not an XPDL file",
            location=SourceLocation(path, 1),
            hint="validate the XPDL it was compiled from; opspec show, run and evaluate "
            "read .wfs scripts directly",
        )
    root, warnings, encoding = _parse(data, path)
    tree = root.getroottree()
    if tree.docinfo.doctype or tree.docinfo.internalDTD is not None:
        raise _doctype_error(path, _doctype_line(data) or 1)
    return ParsedXml(root, tuple(warnings), _big_lines(data, root, encoding))


def xpdl_outcome(parsed: ParsedXml, *, path: str) -> ReadOutcome:
    """``parsed`` as an XPDL package: its version from the root's namespace. Raises
    :class:`XmlReadError` when the root is no XPDL ``Package``."""
    root = parsed.root
    qname = etree.QName(root)
    line = line_of(root)
    if qname.localname != "Package":
        raise XmlReadError(
            "unknown-root",
            f"root element is <{qname.localname}>, not an XPDL <Package> or a BPMN 2.0 "
            "<definitions>",
            location=SourceLocation(path, line),
            hint="give opspec an XPDL package file (its root element is Package) or a BPMN "
            "2.0 file (bpmn:definitions, namespace http://www.omg.org/spec/BPMN/20100524/MODEL)",
        )
    version = version_of_namespace(qname.namespace)
    if version is None:
        known = ", ".join(ns for ns in XPDL_NAMESPACES if ns)
        raise XmlReadError(
            "unknown-version",
            f"unknown XPDL namespace {qname.namespace!r} on <Package>",
            location=SourceLocation(path, line),
            hint=f"use one of {known}, or no namespace",
        )
    return ReadOutcome(root, version, parsed.warnings, parsed.lines)


def read_xml(
    data: bytes, *, path: str, max_bytes: int = DEFAULT_MAX_BYTES
) -> tuple[etree._Element, XpdlVersion]:
    """Parse ``data`` safely; return the root ``Package`` element and the XPDL version.

    Raises :class:`XmlReadError` (with ``path:line``) for anything that is not a readable XPDL
    package: too big, empty, not well-formed, a DOCTYPE, another root element or namespace.
    """
    outcome = read_tree(data, path=path, max_bytes=max_bytes)
    return outcome.root, outcome.version
