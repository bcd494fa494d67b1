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

This module reads an XPDL package (:func:`read_tree`, :func:`read_xml`: the version from the
root's namespace, :func:`xpdl_outcome`) and is the one place its callers import from; the parts
are in modules of their own: the file's bytes under the size limit
(:mod:`opspec.xpdl.read_bytes`), the safe parse whatever the root element
(:mod:`opspec.xpdl.safe_xml`), encodings (:mod:`opspec.xpdl.read_encoding`), the exact lines of
elements past line 65,534 (:mod:`opspec.xpdl.read_lines`) and the fatal errors
(:mod:`opspec.xpdl.read_errors`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from lxml import etree

from opspec.errors import Diagnostic, SourceLocation
from opspec.files import not_a_file
from opspec.model.package import XpdlVersion
from opspec.xpdl.namespaces import XPDL_NAMESPACES, version_of_namespace
from opspec.xpdl.read_bytes import (
    DEFAULT_MAX_BYTES,
    MAX_BYTES_VARIABLE,
    effective_max_bytes,
    read_file,
    read_limited,
)
from opspec.xpdl.read_errors import XmlReadError
from opspec.xpdl.read_lines import copy_line, exact_lines, line_of
from opspec.xpdl.safe_xml import ParsedXml, parse_safely

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


@dataclass(frozen=True, slots=True)
class ReadOutcome:
    """A parsed file: its root element, its version and non-fatal reading warnings.

    ``lines`` holds the exact line of every element past line 65,534 (empty for shorter
    files); :func:`line_of` consults it inside :func:`exact_lines`."""

    root: etree._Element
    version: XpdlVersion
    warnings: tuple[Diagnostic, ...] = ()
    lines: Mapping[etree._Element, int] = field(default_factory=dict)


def read_tree(data: bytes, *, path: str, max_bytes: int = DEFAULT_MAX_BYTES) -> ReadOutcome:
    """Parse ``data`` safely and check that it is an XPDL package. Raises :class:`XmlReadError`."""
    return xpdl_outcome(parse_safely(data, path=path, max_bytes=max_bytes), path=path)


def xpdl_outcome(parsed: ParsedXml, *, path: str) -> ReadOutcome:
    """``parsed`` as an XPDL package: its version from the root's namespace. Raises
    :class:`XmlReadError` when the root is no XPDL ``Package``."""
    root = parsed.root
    qname = etree.QName(root)
    line = line_of(root)
    if qname.localname == "definitions":
        # BPMN's root with its namespace lost or misspelt: "root element is <definitions>, not
        # a BPMN 2.0 <definitions>" would say the same name twice and not why
        where = f"in namespace {qname.namespace!r}" if qname.namespace else "in no namespace"
        raise XmlReadError(
            "unknown-root",
            f"root element <definitions> is {where}, not BPMN 2.0's, so this is no BPMN 2.0 "
            "file (nor an XPDL <Package>)",
            location=SourceLocation(path, line),
            hint="give opspec an XPDL or a BPMN 2.0 file; if this one is BPMN, its namespace "
            "was lost or misspelt: declare it on <definitions>, "
            'xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"',
        )
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
