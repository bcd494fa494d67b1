"""The semantics gate: every element and attribute of a spec that the construct registry
(:mod:`opspec.xpdl.constructs`) marks WARNS or REFUSES, reported at its file:line.

The loader runs it on the file as read (before the XPDL normalising pass renames elements),
so ``opspec validate``, ``run``, ``evaluate``, ``check`` and the walkthrough all see the same
diagnostics: a warning says what opspec does instead of what the standard says, an error
refuses the file. A condition of :data:`CONDITIONS` decides, from the element, its value and
the document around it, whether an entry applies (a quantity of 1 is the default, so it is
quiet; a quantity of 2 is not).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.xpdl.bpmn.event_subprocesses import is_event_sub_process, runnable_event_sub_process
from opspec.xpdl.constructs import (
    BPMN,
    NOT_RUN,
    REPORTED,
    RUNS_DIFFERENTLY,
    XPDL,
    Construct,
    Kind,
)
from opspec.xpdl.gate_starts import triggered_start_in_sub_level, unstarted_by_triggered_starts
from opspec.xpdl.namespaces import is_xpdl_namespace
from opspec.xpdl.reader import line_of

__all__ = ["CONDITIONS", "NOT_RUN", "RUNS_DIFFERENTLY", "Finding", "gate_diagnostics",
           "gate_findings"]

_BPMN_NAMESPACES = frozenset({BPMN, "http://schema.omg.org/spec/BPMN/2.0"})
# Contents kept as written and never run: not walked.
_OPAQUE = frozenset({"ExtendedAttribute", "SchemaType", "extensionElements", "documentation"})
_USER_NAMES = frozenset({"user", "user_lane", "user lane", "users"})
_BPMN_SUBS = frozenset({"subProcess", "adHocSubProcess", "transaction"})


def _local(element: etree._Element) -> str:
    return str(element.tag).rsplit("}", 1)[-1]


def _namespace(element: etree._Element) -> str:
    tag = str(element.tag)
    return tag[1:].split("}", 1)[0] if tag.startswith("{") else ""


def _children(element: etree._Element, *names: str) -> Iterator[etree._Element]:
    for child in element:
        if isinstance(child.tag, str) and _local(child) in names:
            yield child


class _Doc:
    """What conditions need to know about the document around an element, each part computed
    once, on first use (most files need none of it)."""

    def __init__(self, root: etree._Element) -> None:
        self.root = root
        self._by_id: dict[str, etree._Element] | None = None
        self._flows: tuple[dict[str, int], dict[str, list[str]]] | None = None
        self._participants: dict[str, str] | None = None
        # process element -> (has a triggered start event, targets of its flows)
        self.levels: dict[etree._Element, tuple[bool, set[str]]] = {}

    @property
    def by_id(self) -> dict[str, etree._Element]:
        if self._by_id is None:
            found: dict[str, etree._Element] = {}
            for element in self.root.iter(etree.Element):
                ident = element.get("id") or element.get("Id")
                if ident:
                    found.setdefault(ident, element)
            self._by_id = found
        return self._by_id

    def _flow_index(self) -> tuple[dict[str, int], dict[str, list[str]]]:
        if self._flows is None:
            incoming: dict[str, int] = {}
            sources: dict[str, list[str]] = {}
            for flow in self.root.iter("{*}sequenceFlow"):
                target = (flow.get("targetRef") or "").strip()
                incoming[target] = incoming.get(target, 0) + 1
                sources.setdefault(target, []).append((flow.get("sourceRef") or "").strip())
            for transition in self.root.iter("{*}Transition", "Transition"):
                target = (transition.get("To") or "").strip()
                incoming[target] = incoming.get(target, 0) + 1
            self._flows = incoming, sources
        return self._flows

    @property
    def incoming(self) -> dict[str, int]:
        """Flow node id -> number of sequence flows (transitions) into it."""
        return self._flow_index()[0]

    @property
    def sources(self) -> dict[str, list[str]]:
        """Flow node id -> the sources of the sequence flows into it."""
        return self._flow_index()[1]

    @property
    def participant_types(self) -> dict[str, str]:
        """XPDL participant Id -> its ParticipantType (ROLE when not given)."""
        if self._participants is None:
            found: dict[str, str] = {}
            for participant in self.root.iter("{*}Participant", "Participant"):
                ident = participant.get("Id")
                if ident:
                    kind = next(_children(participant, "ParticipantType"), None)
                    found[ident] = ((kind.get("Type") if kind is not None else None)
                                    or "ROLE").upper()
            self._participants = found
        return self._participants


_Condition = Callable[[etree._Element, str | None, _Doc], bool]


def _is(text: str) -> _Condition:
    return lambda element, value, doc: (value or "").strip().lower() == text


def _not_one(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    text = (value or "").strip()
    return bool(text) and text not in ("1", "+1", "01")


def _parent_is(*names: str) -> _Condition:
    def check(element: etree._Element, value: str | None, doc: _Doc) -> bool:
        parent = element.getparent()
        return parent is not None and _local(parent) in names

    return check


def _ancestors(element: etree._Element) -> Iterator[etree._Element]:
    parent = element.getparent()
    while parent is not None:
        yield parent
        parent = parent.getparent()


def _in_event_sub_process(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    return any(_local(a) in _BPMN_SUBS and (a.get("triggeredByEvent") or "").lower() == "true"
               for a in _ancestors(element))


def _refused_event_sub_process(element: etree._Element, value: str | None, doc: _Doc
                               ) -> bool:
    return ((value or "").strip().lower() == "true"
            and not runnable_event_sub_process(element))


def _in_refused_event_sub_process(element: etree._Element, value: str | None, doc: _Doc
                                  ) -> bool:
    host = next((a for a in _ancestors(element) if is_event_sub_process(a)), None)
    return host is not None and not runnable_event_sub_process(host)


def _bpmn_join(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    return doc.incoming.get(element.get("id") or "", 0) > 1


def _inclusive(text: str | None) -> bool:
    return (text or "").strip().lower() in ("inclusive", "or")


def _xpdl_or_join(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    if _local(element) == "Join":
        return _inclusive(element.get("Type"))
    # a Route: its activity's Join (if any) reports; else the gateway joins what arrives
    activity = element.getparent()
    if activity is None or not _inclusive(element.get("GatewayType") or element.get("Type")):
        return False
    has_join = any(_local(e) == "Join" for e in activity.iter() if isinstance(e.tag, str))
    return not has_join and doc.incoming.get(activity.get("Id") or "", 0) > 1


def _terminate_in_sub_process(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    parent = element.getparent()
    return (parent is not None and _local(parent) == "endEvent"
            and any(_local(a) in _BPMN_SUBS for a in _ancestors(parent)))


def _terminate_in_activity_set(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    return ((value or "").strip().lower() == "terminate"
            and any(_local(a) == "ActivitySet" for a in _ancestors(element)))


def _start_events(container: etree._Element) -> list[etree._Element]:
    return list(_children(container, "startEvent"))


def _several_starts(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    if _local(element) == "startEvent":
        parent = element.getparent()
        if parent is None or _in_event_sub_process(element, None, doc):
            return False
        if _local(parent) in _BPMN_SUBS:
            return False            # a sub-process's start events all start with it
        return len(_start_events(parent)) > 1
    # XPDL: Activities/Activity/Event/StartEvent, counted per Activities (a process or a set)
    try:
        activities = element.getparent().getparent().getparent()  # type: ignore[union-attr]
    except AttributeError:
        return False
    if activities is None or _local(activities) != "Activities":
        return False
    owner = activities.getparent()
    if owner is not None and _local(owner) == "ActivitySet":
        return False
    count = sum(1 for activity in _children(activities, "Activity")
                for event in _children(activity, "Event")
                for _start in _children(event, "StartEvent"))
    return count > 1


def _several_none_starts(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    """A BPMN start event without an event definition in a process with another one."""
    if _is_triggered(element) or not _several_starts(element, value, doc):
        return False
    parent = element.getparent()
    assert parent is not None
    return sum(1 for start in _start_events(parent) if not _is_triggered(start)) > 1


def _is_triggered(start: etree._Element) -> bool:
    return any(isinstance(child.tag, str) and _local(child) in _DEFINITIONS for child in start)


_DEFINITIONS = frozenset({
    "messageEventDefinition", "timerEventDefinition", "signalEventDefinition",
    "conditionalEventDefinition", "errorEventDefinition", "escalationEventDefinition",
    "terminateEventDefinition", "linkEventDefinition", "compensateEventDefinition",
    "cancelEventDefinition", "eventDefinitionRef"})


def _several_definitions(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    return sum(1 for child in element
               if isinstance(child.tag, str) and _local(child) in _DEFINITIONS) > 1


def _timer_on_multi_instance(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    if not any(True for _ in _children(element, "timerEventDefinition")):
        return False
    host = doc.by_id.get((element.get("attachedToRef") or "").strip())
    return host is not None and any(True for _ in _children(
        host, "multiInstanceLoopCharacteristics"))


def _non_interrupting_boundary(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    definition = element.getparent()
    event = definition.getparent() if definition is not None else None
    return (event is not None and _local(event) == "boundaryEvent"
            and (event.get("cancelActivity") or "").strip().lower() == "false")


def _attached_timer(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    timer = element.getparent()
    event = timer.getparent() if timer is not None else None
    interrupting = (event.get("Interrupting") or event.get("IsInterrupting") or "true"
                    ) if event is not None else "true"
    return (event is not None and _local(event) == "IntermediateEvent"
            and bool((event.get("Target") or "").strip())
            and interrupting.strip().lower() == "false")


_IGNORED_BOUNDARIES = frozenset({"compensateEventDefinition", "cancelEventDefinition"})


def _ignored_source(source: etree._Element | None) -> bool:
    """A node whose outgoing sequence flows the BPMN reader leaves out: a boundary event
    with a compensation or cancel definition, or with none."""
    if source is None or _local(source) != "boundaryEvent":
        return False
    kinds = {_local(c) for c in source if isinstance(c.tag, str)} & _DEFINITIONS
    return not kinds or bool(kinds & _IGNORED_BOUNDARIES) and len(kinds) == 1


def _fed_only_by_ignored(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    sources = doc.sources.get(element.get("id") or "", [])
    return bool(sources) and all(_ignored_source(doc.by_id.get(s)) for s in sources)


def _on_multi_instance(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    activity = element.getparent()
    if activity is None:
        return False
    for loop in _children(activity, "Loop"):
        if ((loop.get("LoopType") or "").lower() == "multiinstance"
                or any(True for _ in _children(loop, "LoopMultiInstance"))):
            return True
    return False


def _not_a_date(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    """A TimeDate (element text or attribute) that is neither empty nor a date or time of
    day: the reader reads it as a delay expression."""
    from opspec.errors import SpecError
    from opspec.xpdl.durations import parse_time_date

    if value is None:
        value = "".join(element.itertext())
    text = value.strip()
    if not text:
        return False
    try:
        return parse_time_date(text) is None
    except SpecError:
        return False            # an impossible date: the reader's bad-timer error says it


_UNITLESS = re.compile(r"\s*\d+(?:\.\d*)?\s*")


def _unitless_in_other_unit(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    """A time value written as a bare number (element text or attribute) in a process whose
    header's DurationUnit is not seconds: XPDL applies that unit to "an integer duration
    value that has no unit tag"; opspec reads the number as seconds."""
    text = "".join(element.itertext()) if value is None else value
    if not _UNITLESS.fullmatch(text):
        return False
    process = next((a for a in _ancestors(element) if _local(a) == "WorkflowProcess"), None)
    header = next(_children(process, "ProcessHeader"), None) if process is not None else None
    unit = (header.get("DurationUnit") or "").strip() if header is not None else ""
    return unit not in ("", "s")


def _start_activity_overruled(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    """StartActivity="true" on an activity with an incoming transition, in a level that has
    an activity without one: instances start there, not here."""
    if (value or "").strip().lower() != "true" or not doc.incoming.get(element.get("Id") or ""):
        return False
    level = element.getparent()
    return level is not None and any(
        not doc.incoming.get(other.get("Id") or "") for other in _children(level, "Activity"))


def _throws(element: etree._Element, value: str | None, doc: _Doc) -> bool:
    parent = element.getparent()
    return ((element.get("CatchThrow") or "").strip().upper() == "THROW"
            or (parent is not None and _local(parent) == "EndEvent"))


def _manual_mode(activity: etree._Element) -> bool:
    for mode in ("StartMode", "FinishMode"):
        if (activity.get(mode) or "").strip().lower() == "manual":
            return True
        for child in _children(activity, mode):      # XPDL 1.0 <StartMode><Manual/>
            if any(True for _ in _children(child, "Manual")):
                return True
    for attribute in activity.iter():
        if (isinstance(attribute.tag, str) and _local(attribute) == "ExtendedAttribute"
                and (attribute.get("Name") or "") in ("AutoRun", "opspec:AutoRun")
                and (attribute.get("Value") or "").strip().lower() == "false"):
            return True
    return False


def _role_without_implementation(element: etree._Element, value: str | None, doc: _Doc
                                 ) -> bool:
    implementation = next(_children(element, "Implementation"), None)
    if implementation is None:
        return False
    if any(_local(child) != "No" for child in implementation if isinstance(child.tag, str)):
        return False
    performers = [(p.text or "").strip() for p in element.iter()
                  if isinstance(p.tag, str) and _local(p) == "Performer"]
    performers = [p for p in performers if p]
    if not performers or _manual_mode(element):
        return False
    if any(p.lower() in _USER_NAMES for p in performers):
        return False
    # a HUMAN participant's activity is offered to the user lane (manual work): only ROLE
    # (and other non-human) performers make it run by itself
    kinds = [doc.participant_types.get(p) for p in performers]
    return all(kind is not None and kind == "ROLE" for kind in kinds)


#: Condition name (a registry entry's ``when``) -> test of (element, attribute value, doc).
CONDITIONS: dict[str, _Condition] = {
    "true": _is("true"),
    "false": _is("false"),
    "not-one": _not_one,
    "not-all": lambda e, v, d: (v or "All").strip() != "All",
    "parallel": _is("parallel"),
    "present": lambda e, v, d: True,
    "join": _bpmn_join,
    "inclusive-join": _xpdl_or_join,
    "in-event-sub-process": _in_event_sub_process,
    "refused-event-sub-process": _refused_event_sub_process,
    "in-refused-event-sub-process": _in_refused_event_sub_process,
    "in-multi-instance": _parent_is("multiInstanceLoopCharacteristics"),
    "in-sub-process": _terminate_in_sub_process,
    "in-end-event": _parent_is("endEvent", "EndEvent"),
    "in-start-event": _parent_is("startEvent"),
    "in-throw-event": _parent_is("intermediateThrowEvent"),
    "in-boundary-event": _parent_is("boundaryEvent"),
    "several-starts": _several_starts,
    "several-none-starts": _several_none_starts,
    "several-definitions": _several_definitions,
    "timer-on-multi-instance": _timer_on_multi_instance,
    "non-interrupting-boundary": _non_interrupting_boundary,
    "attached-timer": _attached_timer,
    "terminate-in-activity-set": _terminate_in_activity_set,
    "throws": _throws,
    "start-activity-overruled": _start_activity_overruled,
    "unitless-in-other-unit": _unitless_in_other_unit,
    "not-a-date": _not_a_date,
    "on-multi-instance": _on_multi_instance,
    "fed-only-by-ignored": _fed_only_by_ignored,
    "role-without-implementation": _role_without_implementation,
    "unstarted-beside-triggered-start": lambda e, v, d: unstarted_by_triggered_starts(
        e, d.levels),
    "triggered-start-in-sub-level": lambda e, v, d: triggered_start_in_sub_level(e),
}


def _applies(construct: Construct, element: etree._Element, value: str | None,
             doc: _Doc) -> bool:
    if construct.kind is Kind.RUNS:
        return False
    if construct.when is None:
        return True
    return CONDITIONS[construct.when](element, value, doc)


def _opaque(element: etree._Element) -> bool:
    """Inside content kept as written and never run (vendor data, documentation)."""
    return any(_local(a) in _OPAQUE for a in _ancestors(element))


def _label(namespace: str, element: etree._Element, attribute: str | None) -> str:
    prefix = "bpmn:" if namespace == BPMN else ""
    ident = element.get("id") or element.get("Id")
    name = f"{prefix}{_local(element)}" + (f" {ident!r}" if ident else "")
    if not ident:       # a part of something that has an id: say whose (TaskSend of 'notify')
        owner = next((a for a in _ancestors(element) if a.get("id") or a.get("Id")), None)
        if owner is not None and owner.getparent() is not None:
            name += (f" of {prefix}{_local(owner)} "
                     f"{owner.get('id') or owner.get('Id')!r}")
    return f"{name} {attribute}={element.get(attribute)!r}" if attribute else name


def _diagnostic(path: str, construct: Construct, element: etree._Element,
                attribute: str | None) -> Diagnostic:
    severity = Severity.ERROR if construct.kind is Kind.REFUSES else Severity.WARNING
    verb = "is refused" if construct.kind is Kind.REFUSES else "does not run as its standard says"
    hint = construct.hint or f"docs/semantics.md lists what opspec runs ({construct.key})"
    return Diagnostic(SourceLocation(path, line_of(element)), severity, construct.code,
                      f"{_label(construct.namespace, element, attribute)} {verb}: "
                      f"{construct.text} [{construct.section}]", hint)


@dataclass(frozen=True, slots=True)
class Finding:
    """A gate diagnostic and the reader codes that, at the same line, already say it."""

    diagnostic: Diagnostic
    reported_by: tuple[str, ...] = ()


def gate_findings(root: etree._Element, path: str) -> list[Finding]:
    """A finding for every element and attribute of the document at ``root`` that the
    registry marks WARNS or REFUSES (when its condition holds). Run it on the tree as read,
    before the reader rewrites it."""
    bpmn = _namespace(root) in _BPMN_NAMESPACES
    key = BPMN if bpmn else XPDL
    tags = _TAGS[key]
    doc = _Doc(root)
    out: list[Finding] = []
    said_at: dict[str, set[etree._Element]] = {}    # entry key -> elements reported
    # lxml finds the few elements the registry reports (any namespace), in document order
    for element in root.iter(*tags):
        tag = str(element.tag)
        space, _, name = tag[1:].partition("}") if tag[0] == "{" else ("", "", tag)
        if not (space in _BPMN_NAMESPACES if bpmn else is_xpdl_namespace(space)):
            continue
        entries = REPORTED.get((key, name))
        if not entries:
            continue
        said = False
        for attribute, construct in entries:
            if attribute is not None and attribute not in element.attrib:
                continue
            if attribute and construct.when is None and said:
                continue        # ignored with its element, which is already reported
            value = element.get(attribute) if attribute else None
            if _applies(construct, element, value, doc):
                if _opaque(element):
                    break
                if attribute is None:
                    # InputSets/InputSet/Input: the outermost element of a group says it
                    mine = said_at.setdefault(construct.key, set())
                    mine.add(element)
                    if any(a in mine for a in _ancestors(element)):
                        said = True
                        continue
                said = said or attribute is None
                out.append(Finding(_diagnostic(path, construct, element, attribute),
                                   construct.reported_by))
    return out


def _tags(namespace: str) -> tuple[str, ...]:
    names = sorted({name for space, name in REPORTED if space == namespace})
    return (*(f"{{*}}{name}" for name in names), *names)


_TAGS = {BPMN: _tags(BPMN), XPDL: _tags(XPDL)}


def gate_diagnostics(findings: Iterable[Finding], reported: Iterable[Diagnostic] = ()
                     ) -> list[Diagnostic]:
    """The findings' diagnostics, less those the reader already gave (``reported``): an entry
    whose ``reported_by`` code the reader reported at the same line, as severely."""
    said: dict[tuple[int | None, str], set[Severity]] = {}
    for diagnostic in reported:
        said.setdefault((diagnostic.location.line, diagnostic.code), set()).add(
            diagnostic.severity)
    out: list[Diagnostic] = []
    for finding in findings:
        diagnostic = finding.diagnostic
        enough = _AT_LEAST[diagnostic.severity]
        if any(said.get((diagnostic.location.line, code), set()) & enough
               for code in finding.reported_by):
            continue
        out.append(diagnostic)
    return out


_AT_LEAST = {Severity.WARNING: {Severity.WARNING, Severity.ERROR},
             Severity.ERROR: {Severity.ERROR}, Severity.INFO: {Severity.INFO, Severity.WARNING,
                                                              Severity.ERROR}}
