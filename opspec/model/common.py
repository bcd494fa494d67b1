"""Pieces shared by every model element: extended attributes and the ``Element`` base."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TypeVar

from opspec.errors import SourceLocation

__all__ = ["Element", "ExtendedAttribute", "find_by_id", "find_extended"]


@dataclass(frozen=True, slots=True, kw_only=True)
class ExtendedAttribute:
    """An XPDL ``ExtendedAttribute`` kept verbatim so vendor data is never lost.

    ``value`` is the ``Value`` attribute, ``text`` the element's own text content and
    ``raw_xml`` the serialised child elements (exactly as they appeared, namespaces included),
    so a writer can put them back unchanged.
    """

    name: str
    value: str | None = None
    text: str | None = None
    raw_xml: str | None = None
    location: SourceLocation | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Element:
    """Base of model elements that carry an id, a name, a description and vendor data."""

    id: str
    name: str | None = None
    description: str | None = None
    extended_attributes: tuple[ExtendedAttribute, ...] = ()
    location: SourceLocation | None = field(default=None)

    @property
    def label(self) -> str:
        """What to show a user: the name when there is one, else the id."""
        return self.name or self.id


def find_extended(
    attributes: tuple[ExtendedAttribute, ...], name: str
) -> ExtendedAttribute | None:
    """First extended attribute called ``name`` (case-sensitive), or ``None``."""
    for attribute in attributes:
        if attribute.name == name:
            return attribute
    return None


_E = TypeVar("_E", bound=Element)


def find_by_id(elements: Iterable[_E], element_id: str) -> _E | None:
    """The first of ``elements`` whose id is ``element_id``, or None."""
    for element in elements:
        if element.id == element_id:
            return element
    return None
