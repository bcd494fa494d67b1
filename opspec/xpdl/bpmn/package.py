"""BPMN ``definitions`` into a :class:`~opspec.model.package.Package`: the index of the file,
collaborations (pools become participants with their processes; message flows become the
messages between workflows), resources, processes, and the package's opspec extensions
(applications, data fields, metrics, modes, monitors, worlds, run length)."""

from __future__ import annotations

from pathlib import PurePath

from lxml import etree

from opspec.model.package import Package, PackageHeader
from opspec.model.resources import Participant, ParticipantType, Pool
from opspec.xpdl.bpmn.common import (
    BPMN,
    BPMN_BETA,
    BPMNDI,
    Defs,
    bpmn_children,
    first,
    kids,
    local,
    namespace,
    tag,
    text_of,
)
from opspec.xpdl.bpmn.data import CAMUNDA, index_data
from opspec.xpdl.bpmn.extensions import application, data_field, directives, opspec_named
from opspec.xpdl.bpmn.imports import processes_elsewhere
from opspec.xpdl.bpmn.process import BuiltProcess, build_process, is_user_name
from opspec.xpdl.bpmn.run_inputs import with_run_inputs
from opspec.xpdl.bpmn.simulation import BPSIM_NAMESPACES, QBP, read_simulation_parameters
from opspec.xpdl.handlers.common import BuildContext
from opspec.xpdl.namespaces import OPSPEC
from opspec.xpdl.sisarl import PACKAGE_DIRECTIVES, package_extensions

__all__ = ["BPMN_FORMAT", "build_definitions"]

#: What ``validate`` and ``show`` report a BPMN file as (the model stays XPDL 2.1's reading).
BPMN_FORMAT = "BPMN 2.0"

# Root children read elsewhere or harmless: no diagnostic.
_ROOT_QUIET = frozenset({
    "process", "collaboration", "message", "error", "signal", "escalation", "resource",
    "itemDefinition", "interface", "dataStore", "extensionElements", "documentation",
    "import", "category", "correlationProperty", "eventDefinition", "timerEventDefinition",
    "messageEventDefinition", "signalEventDefinition", "errorEventDefinition",
    "escalationEventDefinition", "conditionalEventDefinition", "relationship",
})
_DI_NAMESPACES = frozenset({BPMNDI, "http://www.omg.org/spec/DD/20100524/DI",
                            "http://www.omg.org/spec/DD/20100524/DC"})


def _modernise(root: etree._Element) -> None:
    """Give the elements of a BPMN 2.0 beta file the final namespace (same names)."""
    old = f"{{{BPMN_BETA}}}"
    for element in root.iter():
        if isinstance(element.tag, str) and element.tag.startswith(old):
            element.tag = tag(element.tag[len(old):])


def _index(root: etree._Element, defs: Defs) -> None:
    """Ids, messages, signals, errors, escalations and resources of the file; a repeated id
    is an error (BPMN ids are unique in a file)."""
    ctx = defs.ctx
    prefix = f"{{{BPMN}}}"
    for element in _outside_extensions(root):
        raw = element.tag
        if not isinstance(raw, str) or not raw.startswith(prefix):
            continue
        element_id = element.get("id")
        if not element_id:
            continue
        seen = defs.by_id.get(element_id)
        if seen is not None:
            ctx.error(element, "duplicate-id",
                      f"id {element_id!r} is used twice (first by bpmn:{local(seen)}"
                      f"{defs.line(seen)})", "give every BPMN element its own id")
            continue
        defs.by_id[element_id] = element
        kind = raw[len(prefix):]
        name = (element.get("name") or "").strip() or element_id
        if kind == "message":
            defs.messages[element_id] = name
        elif kind == "signal":
            defs.signals[element_id] = name
        elif kind == "escalation":
            defs.escalations[element_id] = (element.get("escalationCode") or "").strip() or name
        elif kind == "error":
            defs.errors[element_id] = (element.get("errorCode") or "").strip() or name
        elif kind == "resource":
            defs.resources[element_id] = element
    for role in ("humanPerformer", "potentialOwner"):
        for element in root.iter(tag(role)):
            ref = text_of(first(element, "resourceRef"))
            if ref:
                defs.human.add(ref.split(":", 1)[-1] if ref not in defs.resources else ref)


def _outside_extensions(root: etree._Element) -> list[etree._Element]:
    """Every element of the file but those inside ``extensionElements``: a modeller's own
    data there may repeat ids (Visual Paradigm does) without being BPMN elements that
    anything refers to; BPMN's uniqueness of ids is about the model's elements."""
    out: list[etree._Element] = []
    extensions = tag("extensionElements")
    stack = [root]
    while stack:
        element = stack.pop()
        out.append(element)
        if element.tag != extensions:
            stack.extend(reversed([c for c in element if isinstance(c.tag, str)]))
    return out


def _vendor_extensions(root: etree._Element, defs: Defs) -> None:
    """One ``vendor-extension`` note per foreign namespace in extensionElements (Camunda,
    Zeebe, Signavio, SpiffWorkflow…): kept in the file, not run — except Camunda's form
    fields and input/output parameters, which are the process's data (:mod:`.data`)."""
    first_seen: dict[str, etree._Element] = {}
    for extensions in root.iter(tag("extensionElements")):
        for sub in extensions:
            if not isinstance(sub.tag, str) or namespace(sub) in (OPSPEC, BPMN, QBP):
                continue
            if namespace(sub) in BPSIM_NAMESPACES:
                continue                 # simulation parameters: read_simulation_parameters
            if namespace(sub) == CAMUNDA and local(sub) in _CAMUNDA_READ:
                continue
            first_seen.setdefault(namespace(sub), sub)
    for space, element in first_seen.items():
        shown = f"{element.prefix}:{local(element)}" if element.prefix else local(element)
        read = (" (camunda:formData and camunda:inputOutput are read as data)"
                if space == CAMUNDA else "")
        defs.info(element, "vendor-extension",
                  f"extension elements of {space} (first <{shown}>) are not run{read}: opspec "
                  "runs the BPMN elements and its own opspec: extensions",
                  "docs/bpmn.md says how to write what opspec should run")


# Camunda extension elements opspec reads (the data of the process).
_CAMUNDA_READ = frozenset({"formData", "inputOutput"})


def _collaboration(root: etree._Element, defs: Defs) -> list[tuple[str, str | None, str | None,
                                                                 etree._Element]]:
    """The pools ``(participant id, name, processRef, element)``; message flows recorded in
    ``defs.sends``/``defs.receives``."""
    pools: list[tuple[str, str | None, str | None, etree._Element]] = []
    ctx = defs.ctx
    for collaboration in kids(root, "collaboration"):
        for participant in kids(collaboration, "participant"):
            process = (participant.get("processRef") or "").strip() or None
            participant_id = participant.get("id") or ""
            pools.append((participant_id, participant.get("name"), process, participant))
            if process is not None:
                target = defs.by_id.get(process)
                if target is None or local(target) != "process":
                    ctx.error(participant, "unknown-reference",
                              f"pool {participant_id!r}: processRef {process!r} names no "
                              "bpmn:process of this file", "fix the reference")
                else:
                    defs.pool_of.setdefault(process, (participant_id, participant.get("name")))
        for flow in kids(collaboration, "messageFlow"):
            _message_flow(flow, defs)
        for sub in bpmn_children(collaboration):
            if local(sub) not in ("participant", "messageFlow", "extensionElements",
                                  "documentation", "textAnnotation", "association", "group",
                                  "participantAssociation"):
                defs.info(sub, "unsupported-element",
                          f"bpmn:{local(sub)} of the collaboration is not run by opspec; it is "
                          "ignored", "docs/bpmn.md lists what opspec runs")
    return pools


def _message_flow(flow: etree._Element, defs: Defs) -> None:
    flow_id = flow.get("id") or ""
    ends: list[str] = []
    for attribute in ("sourceRef", "targetRef"):
        ref = (flow.get(attribute) or "").strip()
        if ref not in defs.by_id:
            defs.ctx.error(flow, "unknown-reference",
                           f"message flow {flow_id!r}: {attribute} {ref!r} names nothing in "
                           "this file" if ref else f"message flow {flow_id!r} has no {attribute}",
                           f"set {attribute} to the id of a flow node or pool (the flow is "
                           "left out)")
            return
        ends.append(ref)
    message = (flow.get("messageRef") or "").strip()
    if message:
        if message not in defs.messages:
            defs.ctx.error(flow, "unknown-reference",
                           f"message flow {flow_id!r}: messageRef {message!r} names no "
                           "bpmn:message of this file", "fix the reference")
            return
        name = defs.messages[message]
    else:
        name = (flow.get("name") or "").strip() or flow_id
    defs.sends.setdefault(ends[0], []).append((name, flow))
    defs.receives.setdefault(ends[1], []).append((name, flow))


def _participant_type(*names: str | None, human: bool = False,
                      default: ParticipantType = ParticipantType.ROLE) -> ParticipantType:
    return ParticipantType.HUMAN if human or is_user_name(*names) else default


def build_definitions(root: etree._Element, ctx: BuildContext) -> Package:
    """The :class:`Package` of a BPMN ``definitions`` element."""
    if namespace(root) == BPMN_BETA:
        _modernise(root)
    defs = Defs(ctx)
    _index(root, defs)
    index_data(root, defs)
    _vendor_extensions(root, defs)
    simulation = read_simulation_parameters(root, defs)
    defs.probabilities.update(simulation.probabilities)
    defs.probability_source.update(simulation.source)
    defs.durations.update(simulation.durations)
    defs.duration_source.update(simulation.duration_source)
    defs.arrivals.update(simulation.arrivals)
    imported = processes_elsewhere(root, defs)
    defs.call_aliases.update(imported.aliases)
    for sub in root:
        if not isinstance(sub.tag, str):
            continue
        space = namespace(sub)
        if space == QBP or (space == BPMN and local(sub) == "relationship"
                            and any(namespace(e) in BPSIM_NAMESPACES for e in sub.iter()
                                    if isinstance(e.tag, str))):
            defs.info(sub, "simulation-parameters",
                      "simulation parameters (BPSim or QBP): opspec reads their branch "
                      "probabilities, task durations and arrivals; resources, costs and "
                      "calendars are not read (a warning names each)",
                      "docs/bpmn.md, Simulation parameters")
            continue
        if space in _DI_NAMESPACES or (space == BPMN and local(sub) in _ROOT_QUIET):
            continue
        what = f"bpmn:{local(sub)}" if space == BPMN else f"<{local(sub)}> ({space})"
        ctx.warning(sub, "unsupported-element", f"{what} is not run by opspec; it is ignored",
                    "docs/bpmn.md lists what opspec runs")
    pools = _collaboration(root, defs)
    package_fields = tuple(data_field(sub, defs) for sub in opspec_named(root, "DataField"))
    defs.package_fields = {f.id for f in package_fields}
    defs.package_data = {f.id: f for f in package_fields}
    applications = tuple(application(sub, defs) for sub in opspec_named(root, "Application"))
    built: list[BuiltProcess] = [build_process(p, defs) for p in kids(root, "process")]
    if not built:
        ctx.warning(root, "no-process", "the file declares no bpmn:process, so nothing runs "
                    "(pools drawn without a process are only participants)",
                    "draw the flow inside a pool or on the canvas of a process")
    lanes_of = {b.process.id: b.lanes for b in built}
    participants: list[Participant] = []
    for participant_id, name, process, element in pools:
        participants.append(Participant(
            id=participant_id, name=name, location=defs.loc(element),
            type=_participant_type(participant_id, name, default=ParticipantType.SYSTEM)))
    model_pools = tuple(
        Pool(id=participant_id, name=name, process=process, participant=participant_id,
             lanes=lanes_of.get(process or "", ()), location=defs.loc(element))
        for participant_id, name, process, element in pools)
    for pool in model_pools:
        for lane in pool.all_lanes():
            participants.append(Participant(id=lane.id, name=lane.name, location=lane.location,
                                            type=_participant_type(lane.id, lane.name)))
    pooled = {p.process for p in model_pools}
    for b in built:           # lanes of a process drawn without a pool
        if b.process.id not in pooled:
            for lane in b.lanes:
                participants.append(Participant(id=lane.id, name=lane.name,
                                                location=lane.location,
                                                type=_participant_type(lane.id, lane.name)))
    for resource_id, element in defs.resources.items():
        participants.append(Participant(
            id=resource_id, name=element.get("name"), location=defs.loc(element),
            type=_participant_type(resource_id, element.get("name"),
                                   human=resource_id in defs.human)))
    known = {p.id for p in participants}
    if defs.user_participant and "user" not in known:
        participants.append(Participant(id="user", name="User", type=ParticipantType.HUMAN))
    processes, run_inputs = with_run_inputs([b.process for b in built], package_fields, defs)
    # processes called from other files (:mod:`.imports`), with what they need
    processes = [*processes, *imported.processes]
    known = {p.id for p in participants}
    participants.extend(p for p in imported.participants if p.id not in known)
    given = {f.id for f in (*package_fields, *run_inputs)}
    run_inputs = (*run_inputs, *(f for f in imported.data_fields if f.id not in given))
    model_pools = (*model_pools, *imported.pools)
    found, kept = directives(root, defs, PACKAGE_DIRECTIVES, "the definitions",
                             ("DataField", "Application"))
    extensions = package_extensions(root, ctx, found)
    if simulation.run_length and extensions.get("run_length") is None:
        extensions["run_length"] = simulation.run_length[0]     # BPSim's scenario Duration
    stem = PurePath(ctx.path).stem
    return Package(
        id=(root.get("id") or "").strip() or stem,
        name=root.get("name"),
        description=text_of(first(root, "documentation")),
        extended_attributes=kept,
        location=defs.loc(root),
        version=ctx.version,
        source=ctx.path,
        header=PackageHeader(vendor=" ".join(x for x in (root.get("exporter"),
                                                        root.get("exporterVersion")) if x)
                             or None, source_format=BPMN_FORMAT),
        participants=tuple(participants),
        applications=applications,
        data_fields=package_fields + run_inputs,
        pools=model_pools,
        processes=tuple(processes),
        **extensions,
    )
