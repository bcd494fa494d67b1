"""Loops of BPMN activities: ``standardLoopCharacteristics`` (a loop condition, a maximum,
tested before or after) and ``multiInstanceLoopCharacteristics`` (a cardinality, a collection,
a vendor's collection and element variable, a completion condition), as the model's
:class:`~opspec.model.activities.Loop`."""

from __future__ import annotations

import re
from collections.abc import Mapping

from lxml import etree

from opspec.errors import Severity
from opspec.model.activities import Loop, LoopKind, MIFlow
from opspec.model.data import BasicKind, BasicType, DataField, FormalParameter
from opspec.xpdl.bpmn.common import Defs, expression_text, first, label, local, text_of
from opspec.xpdl.bpmn.data import CAMUNDA
from opspec.xpdl.bpmn.scripts import bpmn_condition
from opspec.xpdl.handlers.activities import read_expression
from opspec.xpdl.handlers.common import parse_int

__all__ = ["read_loop"]

_NAME = re.compile(r"^[A-Za-z_]\w*$")


def read_loop(element: etree._Element, defs: Defs,
              declared: Mapping[str, DataField | FormalParameter],
              collections: list[DataField]) -> Loop | None:
    """The ``standardLoopCharacteristics`` or ``multiInstanceLoopCharacteristics`` of an
    activity as the model's :class:`Loop`; ``None`` without one (or when refused at its line).
    ``declared`` are the process's data fields and formal parameters; the element variables of
    collection multi-instances are added to ``collections``."""
    standard = first(element, "standardLoopCharacteristics")
    if standard is not None:
        condition_element = first(standard, "loopCondition")
        text = expression_text(condition_element)
        maximum = parse_int(standard.get("loopMaximum"))
        if text is None and maximum is None:
            defs.ctx.error(standard, "standard-loop-without-end",
                           f"the loop of {label(element)} has neither a loopCondition "
                           "nor a loopMaximum, so it never ends",
                           "add <bpmn:loopCondition> (the activity repeats while it holds) "
                           "or loopMaximum=\"N\"")
        return Loop(kind=LoopKind.STANDARD, condition_text=text,
                    condition=bpmn_condition(condition_element, text, defs,
                                                      "loopCondition"),
                    maximum=maximum,
                    test_before=(standard.get("testBefore") or "").lower() == "true")
    multi = first(element, "multiInstanceLoopCharacteristics")
    if multi is None:
        return None
    cardinality = first(multi, "loopCardinality")
    text = expression_text(cardinality)
    collection = text_of(first(multi, "loopDataInputRef"))
    variable = None
    if text is None and collection is None:
        vendor = _vendor_collection(element, multi, defs, declared, collections)
        if vendor is False:
            return None     # refused at its line; the file does not run
        if vendor is not True:
            text, variable = vendor
    if text is None and collection is not None:
        text = f"len({collection})"
        defs.info(multi, "multi-instance-collection",
                  f"{label(element)} runs one instance per item of {collection!r} "
                  f"(loopCardinality len({collection})); opspec does not hand each "
                  "instance its item", "read the item yourself if an instance needs it")
    completion = first(multi, "completionCondition")
    completion_text = expression_text(completion)
    return Loop(kind=LoopKind.MULTI_INSTANCE, condition_text=text,
                condition=read_expression(
                    cardinality if cardinality is not None else multi, text, defs.ctx,
                    "loopCardinality", severity=Severity.ERROR,
                    hint="write an expression over data fields, e.g. 3 or count + 1"),
                parallel=(multi.get("isSequential") or "false").lower() != "true",
                flow=MIFlow.COMPLEX if completion_text else MIFlow.ALL,
                flow_condition_text=completion_text,
                flow_condition=bpmn_condition(completion, completion_text, defs,
                                              "completionCondition"),
                cancel_remaining=completion_text is not None,
                element_variable=variable)


def _vendor_collection(element: etree._Element, multi: etree._Element, defs: Defs,
                       declared: Mapping[str, DataField | FormalParameter],
                       collections: list[DataField]) -> tuple[str, str | None] | bool:
    """A multi-instance over a vendor's collection (Camunda's ``camunda:collection``/
    ``elementVariable``, Zeebe's ``inputCollection``/``inputElement``): the data field
    holding the list and the element variable's name (without one: the list's length and
    ``None``: one instance per item, none reading it); ``True`` when there is none,
    ``False`` when it is refused at its line.

    Each instance sees its own item under the element variable, over its process
    instance's data (the engine's per-instance overlay), so parallel instances never
    read one another's item. Only a task's instances have it: the activities inside a
    sub-process read their process instance's data, not the overlay, so a sub-process
    or call activity over a collection is refused rather than run with a shared item.
    The collection must be a list data field of the process (or the package); the element
    variable becomes a field of the element's type (so the scripts and conditions reading
    it pass the checks), which each instance reads from its own overlay instead."""
    zeebe = next((sub for sub in multi.iter() if isinstance(sub.tag, str)
                  and local(sub) == "loopCharacteristics"
                  and "zeebe" in (etree.QName(sub).namespace or "")), None)
    items = multi.get(f"{{{CAMUNDA}}}collection")
    variable = multi.get(f"{{{CAMUNDA}}}elementVariable")
    vendor = "camunda:collection", "camunda:elementVariable"
    if items is None and zeebe is not None:
        items, variable = zeebe.get("inputCollection"), zeebe.get("inputElement")
        vendor = "zeebe:inputCollection", "zeebe:inputElement"
    if items is None:
        return True
    text = items.strip()
    text = text[2:-1].strip() if text.startswith("${") and text.endswith("}") else (
        text[1:].strip() if text.startswith("=") else text)
    why = None
    if not _NAME.match(text):
        why = (f"its collection {items.strip()!r} ({vendor[0]}) is no data field's name",
               "name the data field holding the list, e.g. ${scores} (a field with "
               "IsArray=\"true\")")
    elif variable is not None and not _NAME.match(variable.strip()):
        why = (f"its element variable {variable!r} ({vendor[1]}) is no name",
               f"write {vendor[1]}=\"item\"")
    elif variable and local(element) != "task" and not local(element).endswith("Task"):
        why = (f"it is a {local(element)}: the activities inside read their process "
               f"instance's data, not each instance's own {variable.strip()!r}, so "
               "parallel instances would read one another's item",
               "put the multi-instance on the task that uses the item")
    found = declared.get(text) or defs.package_data.get(text)
    if why is None and found is None:
        why = (f"its collection {text!r} is no data field",
               f"declare the list: <opspec:DataField Id={text!r} Type=\"INTEGER\" "
               "IsArray=\"true\" InitialValue=\"[1, 2, 3]\"/>")
    elif why is None and found is not None and not found.is_array:
        why = (f"its collection {text!r} is not a list (IsArray is not true)",
               f"declare {text!r} with IsArray=\"true\" and a JSON list value")
    if variable and _NAME.match(variable.strip()):     # refused or not: no second error
        element_type = (found.type if found is not None and found.is_array
                        else BasicType(kind=BasicKind.STRING))
        collections.append(DataField(id=variable.strip(), type=element_type,
                                          location=defs.loc(multi)))
    if why is not None:
        defs.ctx.error(multi, "multi-instance-without-count",
                       f"{label(element)} runs one instance per item of a list, but "
                       f"{why[0]}", why[1])
        return False
    if not variable:        # one instance per item, none reading it
        return f"len({text})", None
    return text, variable.strip()
