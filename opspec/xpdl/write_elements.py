"""The XPDL 2.1 namespace and what every part of the writer writes elements with: a child
element with its attributes and text (:func:`sub`, attributes that are ``None`` left out), a
wrapper written only around items there are (:func:`each`), XML booleans and NMTOKENs, and
extended attributes written verbatim (``Value``, text and raw child XML).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator, Sequence
from typing import TypeVar

from lxml import etree

from opspec.model import ExtendedAttribute

__all__ = [
    "NSMAP",
    "OPSPEC",
    "XPDL10",
    "XPDL21",
    "append_raw_xml",
    "each",
    "nmtoken",
    "sub",
    "write_extended",
    "xml_bool",
    "xpdl_tag",
]

T = TypeVar("T")

XPDL21 = "http://www.wfmc.org/2008/XPDL2.1"
XPDL10 = "http://www.wfmc.org/2002/XPDL1.0"
OPSPEC = "urn:opspec:sisarl:1"
NSMAP = {None: XPDL21, "opspec": OPSPEC}


def xpdl_tag(local: str) -> str:
    """The tag of the XPDL 2.1 element ``local``."""
    return f"{{{XPDL21}}}{local}"


def sub(parent: etree._Element, local: str, text: str | None = None,
        **attrs: str | None) -> etree._Element:
    """A new XPDL 2.1 child ``local`` of ``parent`` with ``text`` and the attributes that are
    not ``None``."""
    element = etree.SubElement(parent, xpdl_tag(local))
    for key, value in attrs.items():
        if value is not None:
            element.set(key, value)
    if text is not None:
        element.text = text
    return element


def each(parent: etree._Element, wrapper: str,
         items: Sequence[T]) -> Iterator[tuple[etree._Element, T]]:
    """Each of ``items`` with the ``wrapper`` element written for them (XPDL's
    ``<DataFields>``, ``<Transitions>``…); no wrapper at all when there are none."""
    if not items:
        return
    container = sub(parent, wrapper)
    for item in items:
        yield container, item


def xml_bool(value: bool) -> str:
    """An XML Schema boolean."""
    return "true" if value else "false"


_NMTOKEN_BAD = re.compile(r"[^\w.:-]")


def nmtoken(text: str) -> str:
    """``text`` made an NMTOKEN (an Id written from a name): other characters become ``_``."""
    return _NMTOKEN_BAD.sub("_", text) or "_"


_FRAGMENT_PARSER = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)


def append_raw_xml(element: etree._Element, raw_xml: str) -> None:
    """Put the verbatim child XML of an extended attribute back under ``element``."""
    wrapper = f'<w xmlns:opspec="{OPSPEC}">{raw_xml}</w>'
    try:
        parsed = etree.fromstring(wrapper.encode("utf-8"), _FRAGMENT_PARSER)
    except etree.XMLSyntaxError:
        # Not well-formed on its own (it always was in the source): keep it as text.
        element.text = (element.text or "") + raw_xml
        return
    if parsed.text and parsed.text.strip():
        element.text = (element.text or "") + parsed.text
    for child in list(parsed):
        element.append(child)


def write_extended(parent: etree._Element, attributes: Iterable[ExtendedAttribute]) -> None:
    """``parent``'s ``ExtendedAttributes``, each written verbatim."""
    attributes = list(attributes)
    for container, attribute in each(parent, "ExtendedAttributes", attributes):
        element = sub(container, "ExtendedAttribute", Name=attribute.name, Value=attribute.value)
        if attribute.text is not None:
            element.text = attribute.text
        if attribute.raw_xml:
            append_raw_xml(element, attribute.raw_xml)
