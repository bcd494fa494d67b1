"""The construct registry: for every element and attribute of BPMN 2.0 and XPDL 2.x that has
execution semantics, whether opspec RUNS it as its standard says, WARNS (it runs, but as
something else: the text says what opspec does instead) or REFUSES it.

This is the one place that says so. ``opspec validate`` (and so every front door) reports each
WARNS and REFUSES entry whose condition holds at the element's line (:mod:`opspec.xpdl.gate`),
docs/semantics.md's table is generated from it (``python -m opspec.xpdl.constructs``, written
by :mod:`opspec.xpdl.constructs_table`), and tests/semantics_gate/ walks the bundled XSDs and
fails on an element or attribute that is neither here nor in :data:`INERT`.

This module assembles the entries and looks them up (:func:`constructs_for`, :data:`REPORTED`
for the gate, :func:`is_inert`). The entries are written per standard, in
:mod:`opspec.xpdl.constructs_bpmn` and :mod:`opspec.xpdl.constructs_xpdl`; what has no
execution semantics in :mod:`opspec.xpdl.constructs_inert`; what an entry is in
:mod:`opspec.xpdl.construct_entry`.

To record that opspec now runs a construct as its standard says, change its entry's ``kind`` to
``Kind.RUNS`` and its ``text`` to what it does (one place), then regenerate the table.

An entry's ``when`` names a condition of :data:`opspec.xpdl.gate.CONDITIONS` (``None``: the
element or attribute is present); conditions take the value into account, so a value that
changes behaviour (a quantity other than 1, a completionCondition, a cycle) is never read as
its default in silence. ``reported_by`` lists the reader's own diagnostic codes that already
say the same thing at the same line (the gate then adds nothing there).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from opspec.xpdl.construct_entry import (
    BPMN,
    BPMNDI_NAMESPACES,
    NOT_RUN,
    RUNS_DIFFERENTLY,
    XPDL,
    Construct,
    Inert,
    Kind,
)
from opspec.xpdl.constructs_bpmn import BPMN_CONSTRUCTS
from opspec.xpdl.constructs_inert import INERT
from opspec.xpdl.constructs_xpdl import XPDL_CONSTRUCTS

__all__ = [
    "BPMN",
    "BPMNDI_NAMESPACES",
    "CONSTRUCTS",
    "INERT",
    "NOT_RUN",
    "REPORTED",
    "RUNS_DIFFERENTLY",
    "XPDL",
    "Construct",
    "Inert",
    "Kind",
    "constructs_for",
    "is_inert",
]

#: Every entry, BPMN 2.0's then XPDL's (the order of docs/semantics.md's table).
CONSTRUCTS: tuple[Construct, ...] = BPMN_CONSTRUCTS + XPDL_CONSTRUCTS


def _index() -> Mapping[tuple[str, str, str | None], tuple[Construct, ...]]:
    out: dict[tuple[str, str, str | None], list[Construct]] = {}
    for construct in CONSTRUCTS:
        for element in construct.elements:
            out.setdefault((construct.namespace, element, construct.attribute), []).append(
                construct)
    return MappingProxyType({key: tuple(found) for key, found in out.items()})


_BY_KEY = _index()
_EMPTY: tuple[Construct, ...] = ()


def _reported() -> Mapping[tuple[str, str], tuple[tuple[str | None, Construct], ...]]:
    """What the gate looks at: per (namespace, element), its WARNS and REFUSES entries, of the
    element (attribute ``None``) and of its attributes."""
    out: dict[tuple[str, str], list[tuple[str | None, Construct]]] = {}
    for construct in CONSTRUCTS:
        if construct.kind is Kind.RUNS:
            continue
        for element in construct.elements:
            out.setdefault((construct.namespace, element), []).append(
                (construct.attribute, construct))
    # the element's own entries first: an attribute ignored with its element is then quiet
    return MappingProxyType({key: tuple(sorted(found, key=lambda f: f[0] is not None))
                             for key, found in out.items()})


#: (namespace, element) -> ((attribute or None, entry), ...) for WARNS and REFUSES entries.
REPORTED = _reported()


def constructs_for(namespace: str, element: str, attribute: str | None = None
                   ) -> tuple[Construct, ...]:
    """The registry's entries for an element (``attribute`` None) or one of its attributes."""
    return _BY_KEY.get((namespace, element, attribute), _EMPTY)


def is_inert(namespace: str, element: str, attribute: str | None = None) -> str | None:
    """The reason an element or attribute has no execution semantics, or ``None``."""
    for group in INERT:
        if group.namespace != namespace:
            continue
        if "*" not in group.elements and element not in group.elements:
            continue
        if attribute is None:
            if group.include_elements and group.reason:
                return group.reason
        elif ("*" in group.attributes or attribute in group.attributes) and group.reason:
            return group.reason
    return None


if __name__ == "__main__":          # python -m opspec.xpdl.constructs: the docs table
    from opspec.xpdl.constructs_table import markdown_table

    print(markdown_table(), end="")
