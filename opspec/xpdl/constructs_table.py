"""docs/semantics.md's table of what opspec does not run as its standard says, generated
from the construct registry (:mod:`opspec.xpdl.constructs`): one row per WARNS and REFUSES
entry, its ``when`` condition in words. ``python -m opspec.xpdl.constructs`` prints it;
tests/semantics_gate/ fails when it and the docs differ.
"""

from __future__ import annotations

from opspec.xpdl.construct_entry import BPMN, Construct, Kind
from opspec.xpdl.constructs import CONSTRUCTS

__all__ = ["markdown_table"]


def _names(construct: Construct) -> str:
    prefix = "bpmn:" if construct.namespace == BPMN else ""
    names = ", ".join(f"`{prefix}{e}`" for e in construct.elements)
    return f"{names} `@{construct.attribute}`" if construct.attribute else names


_WHEN_TEXT = {
    None: "",
    "true": "when true",
    "false": "when false",
    "not-one": "when not 1",
    "not-all": "when not All",
    "parallel": "when Parallel",
    "present": "when given",
    "join": "as a join (several incoming flows)",
    "inclusive-join": "an inclusive join",
    "in-event-sub-process": "in an event sub-process",
    "refused-event-sub-process": "true, with a start event other than one timer or message",
    "in-refused-event-sub-process": "in an event sub-process opspec does not run",
    "in-multi-instance": "of a multi-instance loop",
    "in-sub-process": "in an embedded sub-process",
    "in-end-event": "in an end event",
    "in-start-event": "in a start event",
    "in-throw-event": "in an intermediate throw event",
    "in-boundary-event": "in a boundary event",
    "several-starts": "several in one process",
    "several-none-starts": "several without an event definition in one process",
    "several-definitions": "with several event definitions",
    "timer-on-multi-instance": "a timer on a multi-instance activity",
    "non-interrupting-boundary": "of a non-interrupting boundary timer",
    "attached-timer": "of a non-interrupting timer attached to an activity",
    "terminate-in-activity-set": "Terminate, in an activity set",
    "throws": "thrown",
    "not-a-date": "a data field or expression, not a date",
    "on-multi-instance": "of a multi-instance activity",
    "fed-only-by-ignored": "all its incoming flows come from ignored elements",
    "role-without-implementation": "no implementation, performed by a ROLE participant",
    "unstarted-beside-triggered-start": "no incoming flow, in a process with a start event "
                                        "that has a trigger",
    "triggered-start-in-sub-level": "with a trigger, in an embedded sub-process or activity set",
}


def markdown_table() -> str:
    """docs/semantics.md's table of what opspec does not run as its standard says (WARNS,
    REFUSES), generated from the registry: tests/semantics_gate/ fails when they differ."""
    lines = ["| standard | construct | when | opspec | what opspec does | section |",
             "|---|---|---|---|---|---|"]
    for construct in CONSTRUCTS:
        if construct.kind is Kind.RUNS:
            continue
        standard = "BPMN 2.0" if construct.namespace == BPMN else "XPDL 2.1"
        when = _WHEN_TEXT.get(construct.when, construct.when)
        text = construct.text.replace("|", "/")
        lines.append(f"| {standard} | {_names(construct)} | {when} | {construct.kind.value} "
                     f"| {text} | {construct.section} |")
    return "\n".join(lines) + "\n"
