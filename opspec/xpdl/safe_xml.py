"""Parsing a specification's bytes into an lxml tree safely, whatever its root element (XPDL
``Package``, BPMN ``definitions``): the size limit (:mod:`opspec.xpdl.read_bytes`), no network,
no DTD loading, no entity expansion, any ``DOCTYPE`` refused outright (XPDL never needs one;
DTDs are how XXE and entity bombs get in), empty files and compiled ``.wfs`` scripts refused,
files that are no XML at all refused saying what they are (:mod:`opspec.xpdl.not_a_spec`),
encodings handled (:mod:`opspec.xpdl.read_encoding`) and the exact lines of elements past line
65,534 found (:mod:`opspec.xpdl.read_lines`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Final

from lxml import etree

from opspec.errors import Diagnostic, SourceLocation
from opspec.xpdl.not_a_spec import not_a_spec
from opspec.xpdl.read_bytes import DEFAULT_MAX_BYTES, effective_max_bytes, too_big_error
from opspec.xpdl.read_encoding import (
    ASCII_NAMES,
    declared_encoding,
    encoding_warning,
    impossible_declaration,
    is_encoding_error,
)
from opspec.xpdl.read_errors import XmlReadError, doctype_error, not_well_formed_error
from opspec.xpdl.read_lines import big_lines

__all__ = ["ParsedXml", "parse_safely"]

_DOCTYPE_MARKERS: Final = (
    b"<!DOCTYPE",
    "<!DOCTYPE".encode("utf-16-le"),
    "<!DOCTYPE".encode("utf-16-be"),
)


@dataclass(frozen=True, slots=True)
class ParsedXml:
    """A file parsed safely, before anyone looked at what its root element is (XPDL
    ``Package``, BPMN ``definitions``): the root, reading warnings and the exact lines past
    65,534 (as in :class:`~opspec.xpdl.reader.ReadOutcome`)."""

    root: etree._Element
    warnings: tuple[Diagnostic, ...] = ()
    lines: Mapping[etree._Element, int] = field(default_factory=dict)


def _parser(encoding: str | None = None) -> etree.XMLParser:
    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=False,
        encoding=encoding,
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


def _declaration_line(data: bytes) -> int:
    at = data.find(b"<?xml")
    return data.count(b"\n", 0, at) + 1 if at >= 0 else 1


def _parse(data: bytes, path: str) -> tuple[etree._Element, list[Diagnostic], str | None]:
    """The root, the reading warnings, and the encoding the parser was told to use (``None``:
    the file's own)."""
    warnings: list[Diagnostic] = []
    declared = declared_encoding(data)
    utf16 = data.startswith((b"\xff\xfe", b"\xfe\xff"))
    # Files that declare ASCII but hold UTF-8 (common in exported fragments): UTF-8 is a superset
    # of ASCII, so reading them as UTF-8 loses nothing and accepts the real content.
    first = "utf-8" if declared in ASCII_NAMES else None
    try:
        return etree.fromstring(data, _parser(first)), warnings, first
    except etree.XMLSyntaxError as error:
        if _has_doctype(data):
            raise doctype_error(path, _doctype_line(data) or error.lineno) from None
        impossible = impossible_declaration(declared, error)
        if impossible is not None:      # said at the declaration's line (blank lines may lead)
            raise XmlReadError("not-well-formed", impossible[0], hint=impossible[1],
                               location=SourceLocation(path, _declaration_line(data)))
        retry = not utf16 and is_encoding_error(error) and declared in (None, "utf-8", *ASCII_NAMES)
        body = data.rstrip(b"\r\n")
        end = (body.count(b"\n") + 1, len(body) - body.rfind(b"\n") - 1)
        if not retry:
            raise not_well_formed_error(path, error, end) from None
        original = error
    try:
        root = etree.fromstring(data, _parser("iso-8859-1"))
    except etree.XMLSyntaxError:
        raise not_well_formed_error(path, original, end) from None
    warnings.append(encoding_warning(data, path, declared, original.lineno or None))
    return root, warnings, "iso-8859-1"


def parse_safely(data: bytes, *, path: str, max_bytes: int = DEFAULT_MAX_BYTES) -> ParsedXml:
    """Parse ``data`` with every protection of this module (size, DOCTYPE, no entities, no
    network, encodings, exact lines), whatever its root element. Raises :class:`XmlReadError`.
    The BPMN reader (:mod:`opspec.xpdl.bpmn`) reads its files through here too."""
    max_bytes = effective_max_bytes(max_bytes, path=path)
    if len(data) > max_bytes:
        raise too_big_error(path, max_bytes)
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
    try:
        root, warnings, encoding = _parse(data, path)
    except XmlReadError as error:
        # a user model, a world file, JSON, a binary file… given as the spec: say what it is
        # and what is wanted, not where libxml2 first stumbled
        wrong = not_a_spec(data, path) if error.code == "not-well-formed" else None
        if wrong is None:
            raise
        message, location, hint = wrong
        raise XmlReadError("not-a-spec", message, location=location, hint=hint) from None
    tree = root.getroottree()
    if tree.docinfo.doctype or tree.docinfo.internalDTD is not None:
        raise doctype_error(path, _doctype_line(data) or 1)
    return ParsedXml(root, tuple(warnings), big_lines(data, root, encoding))
