"""Helpers shared by the structural checks: collecting diagnostics, naming scopes, walking
expressions. Internal to :mod:`opspec.model.checks`."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Protocol

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model.expressions import Binary, Call, Expression, Name, Unary
from opspec.model.package import Package
from opspec.model.process import ActivitySet, WorkflowProcess

__all__ = ["Reporter", "names_read", "quote_list", "where"]


class _Located(Protocol):
    @property
    def location(self) -> SourceLocation | None: ...


class _Identified(_Located, Protocol):
    @property
    def id(self) -> str: ...


def where(process: WorkflowProcess, aset: ActivitySet | None) -> str:
    """How a message names an activity's scope: ``process 'P'`` or
    ``activity set 'S' of process 'P'``."""
    if aset is None:
        return f"process {process.id!r}"
    return f"activity set {aset.id!r} of process {process.id!r}"


def quote_list(ids: Iterable[str]) -> str:
    """``'a', 'b' and 'c'``."""
    quoted = [repr(i) for i in ids]
    if len(quoted) <= 1:
        return "".join(quoted)
    return f"{', '.join(quoted[:-1])} and {quoted[-1]}"


def names_read(expression: Expression | None) -> tuple[str, ...]:
    """Root names (data fields) an expression reads, in first-seen order, without duplicates.

    Same result as :func:`opspec.xpdl.conditions.names_used`, which the model cannot import.
    """
    if expression is None:
        return ()
    found: dict[str, None] = {}
    stack = [expression]
    while stack:
        node = stack.pop()
        if isinstance(node, Name):
            if node.path:
                found.setdefault(node.path[0])
        elif isinstance(node, Unary):
            stack.append(node.operand)
        elif isinstance(node, Binary):
            stack.extend((node.right, node.left))
        elif isinstance(node, Call):
            stack.extend(reversed(node.args))
    return tuple(found)


class Reporter:
    """Collects diagnostics; places each at the element's location, else at the package file."""

    def __init__(self, package: Package) -> None:
        self.package = package
        path = package.source or (package.location.path if package.location else None)
        self.fallback = SourceLocation(path or f"<package {package.id}>")
        self.diagnostics: list[Diagnostic] = []

    def locate(self, thing: _Located | SourceLocation | None) -> SourceLocation:
        if isinstance(thing, SourceLocation):
            return thing
        location = thing.location if thing is not None else None
        return location if location is not None else self.fallback

    def error(self, thing: _Located | SourceLocation | None, code: str, message: str,
              hint: str) -> None:
        self.diagnostics.append(
            Diagnostic(self.locate(thing), Severity.ERROR, code, message, hint))

    def warning(self, thing: _Located | SourceLocation | None, code: str, message: str,
                hint: str) -> None:
        self.diagnostics.append(
            Diagnostic(self.locate(thing), Severity.WARNING, code, message, hint))

    def duplicates(self, elements: Sequence[_Identified], what: str, scope: str) -> None:
        """One ``duplicate-id`` error for every element whose id an earlier one already has."""
        first: dict[str, _Identified] = {}
        for element in elements:
            if not element.id:
                continue          # a missing Id was reported by the reader
            earlier = first.setdefault(element.id, element)
            if earlier is element:
                continue
            line = earlier.location.line if earlier.location is not None else None
            at = f" (first at line {line})" if line is not None else ""
            self.error(element, "duplicate-id",
                       f"{what} id {element.id!r} is used twice in {scope}{at}",
                       f"give every {what} its own Id")
