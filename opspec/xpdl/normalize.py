"""The normalising pass: one XPDL dialect for the handlers.

It runs on the lxml tree after reading and before building, and does two things:

1. every element in any XPDL namespace (1.0, 2.0, 2.1, 2.2 or none) is renamed into
   :data:`~opspec.xpdl.namespaces.CANONICAL`, so handlers are keyed by one namespace (files mix
   them: XPDL 2.0 exports carry ``deprecated:SubFlow`` elements in the 1.0 namespace);
2. XPDL 1.0 (and 2.0) spellings are rewritten into their XPDL 2.1 forms:

   ============================================  ==============================================
   1.0 / 2.0                                     2.1
   ============================================  ==============================================
   ``Implementation/Tool`` (one or more)         ``Implementation/Task/TaskApplication``
   ``BlockActivity@BlockId``                     ``BlockActivity@ActivitySetId``
   ``Activity/Performer``, ``Lane/Performer``    ``…/Performers/Performer``
   ``<StartMode><Automatic/></StartMode>``       ``Activity@StartMode="Automatic"`` (Finish too)
   ``Join/Split@Type`` AND / XOR / OR            Parallel / Exclusive / Inclusive
   ``Route@GatewayType`` AND / XOR / OR          Parallel / Exclusive / Inclusive
   ``Condition`` text                            ``Condition/Expression`` text
   ``Condition`` text beside ``<Expression/>``   ``Condition/Expression`` text (JaWE, TWE)
   ``Deadline/DeadlineCondition``                ``Deadline/DeadlineDuration``
   ``Trigger="Rule"`` + ``TriggerRule``          ``Trigger="Conditional"`` + ``TriggerConditional``
   ============================================  ==============================================

The contents of ``ExtendedAttribute`` and ``SchemaType`` elements are never touched, so vendor
data is kept exactly as written. Each rewrite fires only on its old shape, so the pass is
idempotent and safe on files that mix versions. Line numbers of moved elements are kept.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator

from lxml import etree

from opspec.xpdl.namespaces import CANONICAL, is_xpdl_namespace, qname
from opspec.xpdl.reader import copy_line

__all__ = ["normalize"]

_OPAQUE = frozenset({"ExtendedAttribute", "SchemaType"})
_GATE_SYNONYMS = {"AND": "Parallel", "XOR": "Exclusive", "OR": "Inclusive"}


def _q(local: str) -> str:
    return qname(local, CANONICAL)


_Index = dict[str, list[etree._Element]]
# A tag's fate: (local name, the tag to rename it to or None, opaque?), or None for a foreign
# (vendor) element. Computed once per distinct tag, not once per element.
_Kind = tuple[str, str | None, bool] | None


# The local names the rewrites below look up in the index (no other element is listed).
_INDEXED = frozenset({"Implementation", "Performer", "StartMode", "FinishMode", "Join", "Split",
                      "Route", "Condition", "Deadline", "BlockActivity", "StartEvent",
                      "IntermediateEvent"})


def _kind(tag: str) -> _Kind:
    namespace, local = tag[1:].split("}", 1) if tag.startswith("{") else ("", tag)
    if not is_xpdl_namespace(namespace):
        return None
    return local, (_q(local) if namespace != CANONICAL else None), local in _OPAQUE


def _skip_subtree(elements: Iterator[object], element: etree._Element) -> None:
    """Advance ``elements`` (a document-order ``iter()`` that has just yielded ``element``)
    past ``element``'s descendants."""
    if len(element):
        count = sum(1 for _ in element.iterdescendants())
        next(itertools.islice(elements, count, count), None)


def _canonical_index(root: etree._Element) -> _Index:
    """Rename every element in an XPDL namespace into :data:`CANONICAL` and return the
    canonical elements the rewrites look for (:data:`_INDEXED`) by local name, in document
    order. Foreign (vendor) elements and opaque
    contents are not entered: they are kept verbatim and not indexed. One pass over the tree
    (lxml's own ``iter``), the namespace of each distinct tag worked out once."""
    found: _Index = {}
    kinds: dict[str, _Kind] = {}
    elements = root.iter()
    for element in elements:
        tag = element.tag
        if not isinstance(tag, str):
            continue  # comments, processing instructions
        try:
            kind = kinds[tag]
        except KeyError:
            kind = kinds[tag] = _kind(tag)
        if kind is None:
            _skip_subtree(elements, element)
            continue
        local, renamed, opaque = kind
        if renamed is not None:
            element.tag = renamed
        if local in _INDEXED:
            bucket = found.get(local)
            if bucket is None:
                found[local] = [element]
            else:
                bucket.append(element)
        if opaque:
            _skip_subtree(elements, element)
    return found


def _tools_to_tasks(index: _Index) -> None:
    for implementation in index.get("Implementation", []):
        tools = implementation.findall(_q("Tool"))
        if not tools:
            continue
        task = etree.Element(_q("Task"))
        copy_line(tools[0], task)
        tools[0].addprevious(task)
        for tool in tools:
            tool.tag = _q("TaskApplication")
            task.append(tool)


def _owned(index: _Index, local: str, owners: tuple[str, ...]) -> dict[etree._Element, list[etree._Element]]:
    """The ``local`` elements of the index grouped by their parent, for parents whose local
    name is one of ``owners`` (parents and children in document order)."""
    tags = {_q(owner) for owner in owners}
    grouped: dict[etree._Element, list[etree._Element]] = {}
    for element in index.get(local, ()):
        parent = element.getparent()
        if parent is not None and parent.tag in tags:
            grouped.setdefault(parent, []).append(element)
    return grouped


def _performers(index: _Index) -> None:
    # from the loose Performer elements (few, or none in XPDL 2.x files) to their owners
    for owner, loose in _owned(index, "Performer", ("Activity", "Lane")).items():
        performers = owner.find(_q("Performers"))
        if performers is None:
            performers = etree.Element(_q("Performers"))
            copy_line(loose[0], performers)
            loose[0].addprevious(performers)
        for performer in loose:
            performers.append(performer)


def _modes(index: _Index) -> None:
    # from the (XPDL 1.0) StartMode/FinishMode elements to their activities: the first of each
    for tag in ("StartMode", "FinishMode"):
        for activity, elements in _owned(index, tag, ("Activity",)).items():
            element = elements[0]
            chosen = next((etree.QName(c).localname for c in element if isinstance(c.tag, str)), None)
            if chosen and activity.get(tag) is None:
                activity.set(tag, chosen)
            activity.remove(element)


def _gateways(index: _Index) -> None:
    for tag, attribute in (("Join", "Type"), ("Split", "Type"), ("Route", "GatewayType")):
        for element in index.get(tag, []):
            value = element.get(attribute)
            if value is not None and value.strip().upper() in _GATE_SYNONYMS:
                element.set(attribute, _GATE_SYNONYMS[value.strip().upper()])


def _conditions(index: _Index) -> None:
    for condition in index.get("Condition", []):
        parent = condition.getparent()
        if parent is None or etree.QName(parent).localname != "Transition":
            continue
        expression = condition.find(_q("Expression"))
        if expression is not None:
            # JaWE/TWE write the text beside an empty Expression element
            # (``<Condition Type="CONDITION">x &gt; 1<Expression/></Condition>``): keep it.
            if "".join(expression.itertext()).strip() or len(expression):
                continue
            loose = [condition.text or ""] + [sub.tail or "" for sub in condition]
            if not "".join(loose).strip():
                continue
            expression.text = "".join(loose).strip()
            condition.text = None
            for sub in condition:
                sub.tail = None
            continue
        text = condition.text
        if text is not None and text.strip():
            expression = etree.SubElement(condition, _q("Expression"))
            expression.text = text
            copy_line(condition, expression)
            condition.text = None


def _deadlines(index: _Index) -> None:
    for deadline in index.get("Deadline", []):
        old = deadline.find(_q("DeadlineCondition"))
        if old is not None and deadline.find(_q("DeadlineDuration")) is None:
            old.tag = _q("DeadlineDuration")


def _block_ids(index: _Index) -> None:
    for block in index.get("BlockActivity", []):
        old = block.get("BlockId")
        if old is not None and block.get("ActivitySetId") is None:
            block.set("ActivitySetId", old)
            del block.attrib["BlockId"]


def _rules(index: _Index) -> None:
    for tag in ("StartEvent", "IntermediateEvent"):
        for event in index.get(tag, []):
            if (event.get("Trigger") or "").strip() == "Rule":
                event.set("Trigger", "Conditional")
            rule = event.find(_q("TriggerRule"))
            if rule is not None and event.find(_q("TriggerConditional")) is None:
                rule.tag = _q("TriggerConditional")
                if rule.get("RuleName") is not None and rule.get("ConditionName") is None:
                    rule.set("ConditionName", rule.get("RuleName") or "")


def normalize(root: etree._Element) -> etree._Element:
    """Rewrite ``root`` in place into the canonical namespace and XPDL 2.1 forms; return it."""
    index = _canonical_index(root)
    for rewrite in (_tools_to_tasks, _performers, _modes, _gateways, _conditions, _deadlines,
                    _block_ids, _rules):
        rewrite(index)
    return root
