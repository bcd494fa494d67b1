"""The damage a modeller or a hand editor does to an XPDL or BPMN file, as seeded mutations.

Each operator takes the file's bytes and a ``random.Random`` and returns ``(label, bytes)``
or ``None`` when the file offers it nothing to damage. The tree operators know the two
languages' references (``sourceRef``, ``To``, ``calledElement``, ``<Performer>``…), timers,
conditions and numbers; the byte operators truncate, drop the namespace and change the
encoding declaration. Used by ``benchmarks/mutation_fuzz.py``.
"""

from __future__ import annotations

import random
import re
from collections.abc import Callable

from lxml import etree

__all__ = ["OPERATORS", "mutate"]

PARSER = etree.XMLParser(resolve_entities=False, no_network=True, remove_blank_text=False,
                         huge_tree=True)

# attributes that name another element, in either language
REF_ATTRS = {
    "sourceRef", "targetRef", "attachedToRef", "default", "calledElement", "messageRef",
    "errorRef", "signalRef", "escalationRef", "processRef", "dataObjectRef", "activityRef",
    "From", "To", "Default", "Process", "Participant", "Implementation", "Performer",
    "ActivitySetId", "PackageRef", "ApplicationId", "Lane", "bpmnElement",
}
# elements whose text names another element
REF_TEXTS = {
    "incoming", "outgoing", "sourceRef", "targetRef", "Performer", "flowNodeRef",
    "ExceptionName", "eventDefinitionRef",
}
# elements whose Id attribute names another element
ID_REFS = {"SubFlow", "TaskApplication", "TransitionRef", "Lane", "Application"}
# texts a run reads: conditions, durations, timers
TEXTS = {
    "conditionExpression", "timeDuration", "timeDate", "timeCycle", "Condition", "Expression",
    "Deadline", "DeadlineDuration", "DeadlineCondition", "TimeDate", "TimeCycle", "Duration",
    "Limit", "completionCondition", "loopCondition", "loopCardinality", "script",
    "InitialValue", "ActualParameter", "Cost", "WaitingTime", "WorkingTime",
}
VALUE_TIMES = {"StartTrigger", "Duration", "Deadline", "Period", "RunLength", "MessageTTL"}
NUMBER_ATTRS = {
    "Priority", "Limit", "startQuantity", "completionQuantity", "loopMaximum", "Count",
    "Probability", "Value", "Duration", "Width", "Height", "XCoordinate", "YCoordinate",
    "Length", "Precision", "Scale", "LowerIndex", "UpperIndex", "Instantiation",
}
NUMBER_EA = re.compile(r"Priority|Rate|CpuDemand|Deadline|Duration|RunLength|Period|TTL|"
                       r"Probability|Count|Limit|Seed|Weight|Delay|Interval|Ratio", re.IGNORECASE)
JUNK = ["", "abc", "-1", "1e999", "nan", "PT", "P-1D", "12:99", "R/PT0S", "∞"]


def _local(element: etree._Element) -> str:
    return etree.QName(element).localname if isinstance(element.tag, str) else ""


def _elements(root: etree._Element) -> list[etree._Element]:
    return [e for e in root.iter() if isinstance(e.tag, str)]


def _id_of(element: etree._Element) -> str | None:
    return element.get("Id") or element.get("id")


def _ids(root: etree._Element) -> dict[str, etree._Element]:
    return {i: e for e in _elements(root) for i in [_id_of(e)] if i}


def _pick(rng: random.Random, items: list) -> object:
    return rng.choice(items) if items else None


def _wrong_kind_id(rng: random.Random, root: etree._Element, current: str) -> str:
    """An existing id of another kind of element than ``current`` names, or a missing one."""
    ids = _ids(root)
    kind = _local(ids[current]) if current in ids else ""
    others = [i for i, e in ids.items() if _local(e) != kind]
    if others and rng.random() < 0.6:
        return str(rng.choice(others))
    return rng.choice(["missing_id", current + "_gone", "", " "])


# --- tree operators -------------------------------------------------------------------------

def delete_element(rng, root):
    wanted = [e for e in _elements(root)[1:] if _local(e) in {
        "Activity", "Transition", "sequenceFlow", "task", "userTask", "serviceTask",
        "scriptTask", "exclusiveGateway", "parallelGateway", "inclusiveGateway",
        "eventBasedGateway", "startEvent", "endEvent", "intermediateCatchEvent",
        "boundaryEvent", "Participant", "DataField", "Application", "WorkflowProcess",
        "process", "message", "error", "signal", "Implementation", "Route", "Event",
        "StartEvent", "EndEvent", "TriggerTimer", "timerEventDefinition", "ExtendedAttribute",
        "Performer", "Lane", "Pool", "conditionExpression", "Condition", "SubFlow",
        "callActivity", "subProcess", "laneSet", "lane", "definitions", "Split", "Join",
        "TransitionRestriction", "Participants", "Activities", "Transitions", "DataType",
        "BasicType", "ActivitySet", "messageFlow", "collaboration", "participant"}]
    element = _pick(rng, wanted or _elements(root)[1:])
    if element is None or element.getparent() is None:
        return None
    element.getparent().remove(element)
    return f"delete <{_local(element)} {_id_of(element) or ''}>"


def delete_attribute(rng, root):
    pairs = [(e, k) for e in _elements(root) for k in e.attrib]
    pair = _pick(rng, pairs)
    if pair is None:
        return None
    element, key = pair
    del element.attrib[key]
    return f"delete {_local(element)}/@{etree.QName(key).localname}"


def duplicate_id(rng, root):
    holders = [e for e in _elements(root) if _id_of(e)]
    if len(holders) < 2:
        return None
    a, b = rng.sample(holders, 2)
    key = "Id" if b.get("Id") is not None else "id"
    b.set(key, _id_of(a) or "")
    return f"duplicate id {_id_of(a)!r} on <{_local(b)}>"


def dangle_reference(rng, root):
    sites = [(e, k) for e in _elements(root) for k in e.attrib
             if etree.QName(k).localname in REF_ATTRS
             or (k == "Id" and _local(e) in ID_REFS)]
    sites += [(e, None) for e in _elements(root)
              if _local(e) in REF_TEXTS and (e.text or "").strip()]
    site = _pick(rng, sites)
    if site is None:
        return None
    element, key = site
    current = (element.get(key) if key else element.text) or ""
    new = _wrong_kind_id(rng, root, current.strip())
    if key:
        element.set(key, new)
    else:
        element.text = new
    return f"point {_local(element)}/{etree.QName(key).localname if key else 'text()'} " \
           f"{current.strip()!r} at {new!r}"


def empty_text(rng, root):
    sites = [e for e in _elements(root) if _local(e) in TEXTS]
    # XPDL 2.x timers carry their value in attributes
    sites += [e for e in _elements(root) if _local(e) == "TriggerTimer"]
    # opspec's own timers and durations: <opspec:StartTrigger Value=…>, ExtendedAttributes
    sites += [e for e in _elements(root) if e.get("Value") is not None and (
        _local(e) in VALUE_TIMES or VALUE_TIMES.intersection([e.get("Name", "")[7:]]))]
    element = _pick(rng, sites)
    if element is None:
        return None
    junk = rng.choice(JUNK)
    if element.get("Value") is not None:
        old = element.get("Value") or ""
        # emptied, junk, or the time part of a trigger damaged ("timer:" kept)
        element.set("Value", old.split(":", 1)[0] + ":" + junk if ":" in old and
                    rng.random() < 0.5 else junk)
        return f"{_local(element)} {element.get('Name', '')} Value {old!r} -> " \
               f"{element.get('Value')!r}"
    if _local(element) == "TriggerTimer" and not (element.text or "").strip():
        for key in element.attrib:
            element.set(key, junk)
        for child in element:
            child.text = junk
    else:
        for child in list(element):
            if _local(child) in {"Expression"} or rng.random() < 0.5:
                element.remove(child)
        element.text = junk
    return f"text of <{_local(element)}> -> {junk!r}"


def not_a_number(rng, root):
    sites = [(e, k) for e in _elements(root) for k in e.attrib
             if etree.QName(k).localname in NUMBER_ATTRS]
    sites += [(e, "Value") for e in _elements(root)
              if _local(e) == "ExtendedAttribute" and NUMBER_EA.search(e.get("Name", ""))]
    site = _pick(rng, sites)
    if site is None:
        return None
    element, key = site
    junk = rng.choice(["abc", "", "-5", "1e999", "nan", "0x10", "1,5", "inf"])
    element.set(key, junk)
    return f"{_local(element)} {element.get('Name', '')}/@{key} -> {junk!r}"


def self_subflow(rng, root):
    calls = [e for e in _elements(root) if _local(e) in {"SubFlow", "callActivity"}]
    processes = {e: p for e in calls for p in e.iterancestors()
                 if _local(p) in {"WorkflowProcess", "process"}}
    call = _pick(rng, list(processes))
    if call is None:
        # no call yet: turn a task into a call of its own process
        tasks = [e for e in _elements(root) if _local(e) in {"task", "Implementation"}]
        task = _pick(rng, tasks)
        if task is None:
            return None
        process = next((p for p in task.iterancestors()
                        if _local(p) in {"WorkflowProcess", "process"}), None)
        if process is None:
            return None
        if _local(task) == "task":
            task.tag = etree.QName(task).namespace and \
                f"{{{etree.QName(task).namespace}}}callActivity" or "callActivity"
            task.set("calledElement", _id_of(process) or "")
        else:
            for child in list(task):
                task.remove(child)
            sub = etree.SubElement(task, f"{{{etree.QName(task).namespace}}}SubFlow"
                                   if etree.QName(task).namespace else "SubFlow")
            sub.set("Id", _id_of(process) or "")
        return f"make {_id_of(task.getparent()) or _id_of(task)} call its own process"
    process = processes[call]
    call.set("Id" if _local(call) == "SubFlow" else "calledElement", _id_of(process) or "")
    return f"{_local(call)} calls its own process {_id_of(process)!r}"


def swap_start_end(rng, root):
    starts = [e for e in _elements(root) if _local(e) in {"startEvent", "StartEvent"}]
    ends = [e for e in _elements(root) if _local(e) in {"endEvent", "EndEvent"}]
    if not starts or not ends:
        return None
    start, end = rng.choice(starts), rng.choice(ends)
    start.tag, end.tag = end.tag, start.tag
    return f"swap start {_id_of(start) or _id_of(start.getparent())} and end " \
           f"{_id_of(end) or _id_of(end.getparent())}"


def gateway_without_outgoing(rng, root):
    gateways = [e for e in _elements(root) if _local(e).endswith("Gateway")]
    gateways += [e.getparent() for e in _elements(root) if _local(e) == "Route"]
    gateway = _pick(rng, [g for g in gateways if g is not None])
    if gateway is None:
        return None
    gid = _id_of(gateway)
    removed = 0
    for flow in _elements(root):
        if (_local(flow) == "sequenceFlow" and flow.get("sourceRef") == gid) or \
                (_local(flow) == "Transition" and flow.get("From") == gid):
            flow.getparent().remove(flow)
            removed += 1
    for child in list(gateway):
        if _local(child) == "outgoing":
            gateway.remove(child)
    return f"gateway {gid!r} loses its {removed} outgoing flows"


# --- byte operators --------------------------------------------------------------------------

def drop_namespace(rng, data: bytes) -> tuple[str, bytes] | None:
    found = list(re.finditer(rb'\sxmlns(:\w+)?="[^"]*"', data))
    if not found:
        return None
    match = rng.choice(found)
    if rng.random() < 0.5:
        return f"drop {match.group(0).strip().decode('utf-8', 'replace')}", \
            data[:match.start()] + data[match.end():]
    uri = re.sub(rb'="[^"]*"', b'="http://example.com/wrong"', match.group(0))
    return f"wrong namespace for {match.group(0).strip().decode('utf-8', 'replace')}", \
        data[:match.start()] + uri + data[match.end():]


def truncate(rng, data: bytes) -> tuple[str, bytes] | None:
    if len(data) < 2:
        return None
    at = rng.randrange(1, len(data))
    return f"truncate at byte {at} of {len(data)}", data[:at]


def change_encoding(rng, data: bytes) -> tuple[str, bytes] | None:
    new = rng.choice([b"UTF-16", b"ISO-8859-1", b"bogus-8", b"ascii", b"UTF-32", b""])
    declared = re.match(rb'<\?xml[^>]*?encoding=["\']([^"\']*)["\']', data)
    if declared:
        data = data[:declared.start(1)] + new + data[declared.end(1):]
    elif data.startswith(b"<?xml"):
        data = data.replace(b"?>", b' encoding="' + new + b'"?>', 1)
    else:
        data = b'<?xml version="1.0" encoding="' + new + b'"?>\n' + data
    if rng.random() < 0.3:   # and a byte that is no UTF-8 in a name
        at = data.find(b"Name=\"")
        if at > 0:
            data = data[:at + 6] + b"\xe9\xff" + data[at + 6:]
    return f"encoding declared {new.decode()!r}", data


TREE_OPERATORS: dict[str, Callable] = {
    "delete-element": delete_element, "delete-attribute": delete_attribute,
    "duplicate-id": duplicate_id, "dangling-reference": dangle_reference,
    "empty-text": empty_text, "not-a-number": not_a_number, "self-subflow": self_subflow,
    "swap-start-end": swap_start_end, "gateway-no-outgoing": gateway_without_outgoing,
}
BYTE_OPERATORS: dict[str, Callable] = {
    "drop-namespace": drop_namespace, "truncate": truncate, "encoding": change_encoding,
}
OPERATORS = [*TREE_OPERATORS, *BYTE_OPERATORS]


def mutate(data: bytes, operator: str, rng: random.Random) -> tuple[str, bytes] | None:
    """One mutant of ``data`` by ``operator``, or None when it has nothing to damage."""
    if operator in BYTE_OPERATORS:
        return BYTE_OPERATORS[operator](rng, data)
    try:
        tree = etree.ElementTree(etree.fromstring(data, PARSER))
    except etree.XMLSyntaxError:
        return None
    label = TREE_OPERATORS[operator](rng, tree.getroot())
    if label is None:
        return None
    declared = re.match(rb'<\?xml[^>]*?encoding=["\']([^"\']*)["\']', data)
    encoding = declared.group(1).decode() if declared else "UTF-8"
    try:
        out = etree.tostring(tree, xml_declaration=data.startswith(b"<?xml"),
                             encoding=encoding)
    except LookupError:
        out = etree.tostring(tree, xml_declaration=True, encoding="UTF-8")
    return label, out
