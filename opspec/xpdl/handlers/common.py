"""What every handler shares: the build context (file, diagnostics) and tree helpers.

Handlers run on a *normalised* tree (:mod:`opspec.xpdl.normalize`): every XPDL element is in
:data:`~opspec.xpdl.namespaces.CANONICAL` and uses its XPDL 2.1 spelling.
"""

from __future__ import annotations

import copy
import enum
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any, TypeAlias, TypeVar

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model.common import ExtendedAttribute
from opspec.model.package import XpdlVersion
from opspec.xpdl.namespaces import CANONICAL, qname
from opspec.xpdl.reader import line_of

__all__ = [
    "BuildContext",
    "attr",
    "base_fields",
    "child",
    "child_text",
    "children",
    "children_by_tag",
    "enum_attr",
    "extended_attributes",
    "grandchildren",
    "indexed_children",
    "local_name",
    "parse_bool",
    "parse_int",
    "quantity",
    "raw_xml",
    "required_attr",
    "text_of",
]

T = TypeVar("T")
E = TypeVar("E", bound=enum.Enum)
Node: TypeAlias = etree._Element


@dataclass(slots=True)
class BuildContext:
    """One file being built: where it is, its version, and the diagnostics found so far."""

    path: str
    version: XpdlVersion
    diagnostics: list[Diagnostic] = field(default_factory=list)

    def loc(self, element: Node | None) -> SourceLocation:
        return SourceLocation(self.path, line_of(element) if element is not None else None)

    def report(
        self, element: Node | None, severity: Severity, code: str, message: str, hint: str = ""
    ) -> None:
        self.diagnostics.append(Diagnostic(self.loc(element), severity, code, message, hint))

    def error(self, element: Node | None, code: str, message: str, hint: str = "") -> None:
        self.report(element, Severity.ERROR, code, message, hint)

    def warning(self, element: Node | None, code: str, message: str, hint: str = "") -> None:
        self.report(element, Severity.WARNING, code, message, hint)

    def each(self, elements: list[Node], build: Callable[[Node, BuildContext], T | None]) -> tuple[T, ...]:
        """Build every element, dropping those whose handler gave ``None``."""
        out: list[T] = []
        for element in elements:
            value = build(element, self)
            if value is not None:
                out.append(value)
        return tuple(out)


def local_name(element: Node) -> str:
    tag = element.tag
    if not isinstance(tag, str):
        return ""
    return tag.rsplit("}", 1)[-1]


# The canonical tag of each local name asked for (``{CANONICAL}local``), made once.
_TAGS: dict[str, str] = {}
# Inside :func:`indexed_children`: element -> its element children by tag, each element's
# children walked once however many child()/children() calls ask about them. Bounded: cleared
# when full (a handler asks about one element and its near descendants at a time).
_BY_TAG: ContextVar[dict[Node, dict[str, list[Node]]] | None] = ContextVar(
    "opspec_children_by_tag", default=None)
_BY_TAG_LIMIT = 256


@contextmanager
def indexed_children() -> Iterator[None]:
    """Within this block :func:`child` and :func:`children` index each element's children
    once (the tree must not change meanwhile: handlers only read it)."""
    token = _BY_TAG.set({})
    try:
        yield
    finally:
        _BY_TAG.reset(token)


def _tag(local: str) -> str:
    tag = _TAGS.get(local)
    if tag is None:
        tag = _TAGS[local] = qname(local, CANONICAL)
    return tag


def _index_children(element: Node, cache: dict[Node, dict[str, list[Node]]]
                    ) -> dict[str, list[Node]]:
    """``element``'s element children by tag (document order), remembered in ``cache``."""
    if len(cache) >= _BY_TAG_LIMIT:
        cache.clear()
    found: dict[str, list[Node]] = {}
    for sub in element:
        tag = sub.tag
        if isinstance(tag, str):
            bucket = found.get(tag)
            if bucket is None:
                found[tag] = [sub]
            else:
                bucket.append(sub)
    cache[element] = found
    return found


def children_by_tag(element: Node) -> dict[str, list[Node]] | None:
    """``element``'s element children by tag (in the order each tag first occurs) inside
    :func:`indexed_children`; ``None`` outside it. Not to be changed by the caller."""
    cache = _BY_TAG.get()
    if cache is None:
        return None
    return cache.get(element) or _index_children(element, cache)


def child(element: Node, local: str) -> Node | None:
    if not len(element):
        return None
    tag = _TAGS.get(local) or _tag(local)
    cache = _BY_TAG.get()
    if cache is not None:
        found = (cache.get(element) or _index_children(element, cache)).get(tag)
        return found[0] if found else None
    # iterchildren, not find(): no ElementPath to look up on each of a big file's many calls
    return next(element.iterchildren(tag), None)


def children(element: Node | None, local: str) -> list[Node]:
    if element is None or not len(element):
        return []
    tag = _TAGS.get(local) or _tag(local)
    cache = _BY_TAG.get()
    if cache is not None:
        found = (cache.get(element) or _index_children(element, cache)).get(tag)
        return list(found) if found else []
    return list(element.iterchildren(tag))


def grandchildren(element: Node, wrapper: str, local: str) -> list[Node]:
    """``element/wrapper/local`` over every ``wrapper`` (files sometimes repeat wrappers)."""
    out: list[Node] = []
    for group in children(element, wrapper):
        # a wrapper is asked about once: its children are not indexed (one filtered pass)
        if len(group):
            out.extend(group.iterchildren(_TAGS.get(local) or _tag(local)))
    return out


def text_of(element: Node | None) -> str | None:
    """The element's stripped text, or ``None`` when absent or blank."""
    if element is None or element.text is None:
        return None
    text = element.text.strip()
    return text or None


def child_text(element: Node, local: str) -> str | None:
    return text_of(child(element, local))


def attr(element: Node, name: str) -> str | None:
    """An attribute's stripped value, ``None`` when absent or blank."""
    value = element.get(name)
    if value is None:
        return None
    value = value.strip()
    return value or None


def required_attr(element: Node, name: str, ctx: BuildContext, code: str, message: str,
                  hint: str) -> str:
    """The value of an attribute the element cannot do without (the Id a reference names);
    when it is absent or blank, a located ``code`` error and ``""``, so that reading goes on
    and every other error of the spec is reported too."""
    value = attr(element, name)
    if value is None:
        ctx.error(element, code, message, hint)
        return ""
    return value


def enum_attr(element: Node, name: str, default: E, ctx: BuildContext, code: str,
              what: str, hint: str) -> E:
    """Attribute ``name`` as a member of ``default``'s enumeration (its value upper-cased);
    ``default`` when it is absent, and when it is unknown too, with a located ``code``
    warning that names ``what``."""
    raw = attr(element, name)
    if raw is None:
        return default
    try:
        return type(default)(raw.upper())
    except ValueError:
        ctx.warning(element, code, f"unknown {what} {raw.upper()!r}; {default.value} assumed",
                    hint)
        return default


def parse_bool(text: str | None) -> bool | None:
    if text is None:
        return None
    lowered = text.strip().lower()
    if lowered in ("true", "1", "yes"):
        return True
    if lowered in ("false", "0", "no"):
        return False
    return None


def quantity(element: Node, name: str, ctx: BuildContext) -> int:
    """A token quantity attribute (XPDL StartQuantity, CompletionQuantity, Transition
    Quantity; BPMN startQuantity, completionQuantity): 1 when absent; anything but a whole
    number >= 1 is a ``bad-quantity`` error (read as 1, never silently)."""
    text = attr(element, name)
    if text is None:
        return 1
    value = parse_int(text)
    if value is None or value < 1:
        ctx.error(element, "bad-quantity", f"{name} {text!r} is not a whole number of tokens "
                  "(1 or more)", f"write {name}=\"2\", or leave it out for 1")
        return 1
    return value


def parse_int(text: str | None) -> int | None:
    if text is None:
        return None
    try:
        return int(text.strip())
    except ValueError:
        try:
            number = float(text.strip())
        except ValueError:
            return None
        return int(number) if number.is_integer() else None


def raw_xml(element: Node) -> str:
    """``element`` serialised on its own, declaring only the namespaces it uses."""
    alone = copy.deepcopy(element)
    alone.tail = None
    etree.cleanup_namespaces(alone)
    return str(etree.tostring(alone, encoding="unicode"))


def _raw_children(element: Node) -> str | None:
    return "".join(raw_xml(sub) for sub in element if isinstance(sub.tag, str)) or None


def extended_attributes(element: Node, ctx: BuildContext) -> tuple[ExtendedAttribute, ...]:
    """Every ``ExtendedAttributes/ExtendedAttribute`` of ``element``, kept verbatim."""
    if not len(element):
        return ()
    out: list[ExtendedAttribute] = []
    for ext in grandchildren(element, "ExtendedAttributes", "ExtendedAttribute"):
        name = ext.get("Name")
        if name is None:
            ctx.warning(ext, "extended-attribute-without-name",
                        "ExtendedAttribute has no Name; it is kept with an empty name",
                        "give every ExtendedAttribute a Name")
            name = ""
        out.append(
            ExtendedAttribute(
                name=name,
                value=ext.get("Value"),
                text=ext.text if ext.text is not None and ext.text.strip() else None,
                raw_xml=_raw_children(ext),
                location=ctx.loc(ext),
            )
        )
    return tuple(out)


def base_fields(
    element: Node, ctx: BuildContext, *, kind: str, id_default: str | None = None
) -> dict[str, Any]:
    """The :class:`~opspec.model.common.Element` fields (id, name, description, extended
    attributes, location). A missing Id is an error (the element gets a placeholder id) unless
    ``id_default`` is given (elements whose Id is optional)."""
    element_id = attr(element, "Id") or id_default
    if element_id is None:
        line = line_of(element)
        element_id = f"<{kind} without Id at line {line}>" if line else f"<{kind} without Id>"
        ctx.error(element, "missing-id", f"{kind} has no Id",
                  f"add an Id attribute to the {kind}")
    nested = len(element)
    description = child_text(element, "Description") if nested else None
    if description is None:
        description = attr(element, "Description")
    return {
        "id": element_id,
        "name": attr(element, "Name"),
        "description": description,
        "extended_attributes": extended_attributes(element, ctx) if nested else (),
        "location": ctx.loc(element),
    }
