"""Registries of small handlers keyed by ``(namespace, local name)``.

Each registry answers one question about an element's children (what data type is this, what
kind of activity body, which task, which event). Handlers are plain functions
``(element, ctx) -> value`` registered with a decorator, so adding support for an element is
one function in one place.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Generic, TypeVar

from lxml import etree

from opspec.xpdl.handlers.common import BuildContext, children_by_tag
from opspec.xpdl.namespaces import CANONICAL, qname

__all__ = ["Handler", "Registry"]

T = TypeVar("T")
Handler = Callable[[etree._Element, BuildContext], T]


class Registry(Generic[T]):
    """Handlers for one family of elements (``what`` names the family in messages)."""

    def __init__(self, what: str) -> None:
        self.what = what
        self._handlers: dict[str, Callable[[etree._Element, BuildContext], T]] = {}

    def register(
        self, local: str, namespace: str = CANONICAL
    ) -> Callable[[Callable[[etree._Element, BuildContext], T]], Callable[[etree._Element, BuildContext], T]]:
        def decorate(
            function: Callable[[etree._Element, BuildContext], T],
        ) -> Callable[[etree._Element, BuildContext], T]:
            self._handlers[qname(local, namespace)] = function
            return function

        return decorate

    def names(self) -> tuple[str, ...]:
        """Local names handled, for messages listing what is allowed."""
        return tuple(sorted(tag.rsplit("}", 1)[-1] for tag in self._handlers))

    def handles(self, element: etree._Element) -> bool:
        return isinstance(element.tag, str) and element.tag in self._handlers

    def matching(self, parent: etree._Element) -> Iterator[etree._Element]:
        """Children of ``parent`` that have a handler, in document order."""
        for element in parent:
            if self.handles(element):
                yield element

    def build(self, element: etree._Element, ctx: BuildContext) -> T:
        return self._handlers[str(element.tag)](element, ctx)

    def first(self, parent: etree._Element) -> etree._Element | None:
        """The first child of ``parent`` with a handler (document order), or ``None``."""
        by_tag = children_by_tag(parent) if len(parent) else {}
        if by_tag is None:
            return next(self.matching(parent), None)
        # each tag's first child, in the order the tags first occur: the first one handled is
        # the first handled child
        for tag, found in by_tag.items():
            if tag in self._handlers:
                return found[0]
        return None

    def build_first(self, parent: etree._Element, ctx: BuildContext) -> T | None:
        """Build the first child of ``parent`` with a handler, or ``None`` if none has one."""
        for element in self.matching(parent):
            return self.build(element, ctx)
        return None
