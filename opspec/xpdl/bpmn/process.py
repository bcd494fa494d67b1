"""BPMN processes into :class:`~opspec.model.process.WorkflowProcess` values: flow nodes,
sequence flows (conditions, default flows), sub-processes (activity sets), boundary events,
loops, lanes and performers, data.

Boundary events are read in :mod:`.boundaries`, loops in :mod:`.loops`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable
from dataclasses import dataclass

from lxml import etree

from opspec.model.activities import (
    Activity,
    ActivityBody,
    BlockActivity,
    Event,
    GatewayType,
    Join,
    Mode,
    NoImplementation,
    Split,
    Task,
    TaskKind,
)
from opspec.model.data import Assignment, BasicType, DataField, FormalParameter
from opspec.model.process import ActivitySet, Condition, ConditionKind, Transition, WorkflowProcess
from opspec.model.resources import Lane
from opspec.model.sisarl import ActivityDirectives, ProcessDirectives
from opspec.xpdl.bpmn.boundaries import Boundaries, read_boundaries
from opspec.xpdl.bpmn.branches import decide_undecided
from opspec.xpdl.bpmn.common import (
    BPMN,
    Defs,
    expression_text,
    first,
    kids,
    label,
    literal_kind,
    local,
    namespace,
    text_of,
)
from opspec.xpdl.bpmn.data import activity_data, process_fields
from opspec.xpdl.bpmn.event_subprocesses import hoist_event_sub_processes
from opspec.xpdl.bpmn.extensions import (
    assignments,
    data_field,
    directives,
    formal_parameter,
    opspec_named,
)
from opspec.xpdl.bpmn.loops import read_loop
from opspec.xpdl.bpmn.nodes import NODES, build_node
from opspec.xpdl.bpmn.scripts import bpmn_condition
from opspec.xpdl.handlers.common import quantity
from opspec.xpdl.sisarl import (
    ACTIVITY_DIRECTIVES,
    PROCESS_DIRECTIVES,
    Directive,
    activity_directives,
    process_directives,
)

__all__ = ["BuiltProcess", "build_process", "is_user_name"]

_SUB_PROCESSES = frozenset({"subProcess", "transaction", "adHocSubProcess"})
# Read elsewhere, or documentation only: no diagnostic.
_QUIET = frozenset({
    "laneSet", "documentation", "extensionElements", "dataObject", "dataObjectReference",
    "dataStoreReference", "textAnnotation", "association", "group", "property", "incoming",
    "outgoing", "sequenceFlow", "boundaryEvent", "ioSpecification", "ioBinding", "auditing",
    "monitoring", "supports", "dataInputAssociation", "dataOutputAssociation",
    "standardLoopCharacteristics", "multiInstanceLoopCharacteristics", "completionCondition",
    "correlationSubscription", "categoryValue",
})
_USER_NAMES = frozenset({"user", "users", "user lane", "user_lane", "the user"})
_ACTIVITY_STRUCTURE = ("TaskApplication", "ActualParameter", "Assignment", "Execution")

def is_user_name(*names: str | None) -> bool:
    """True when one of ``names`` (a lane's, a pool's, a resource's id or name) names the
    user: ``User``, ``Users``, ``User lane``… (the names the engine's user lane goes by)."""
    return any(n is not None and n.strip().lower() in _USER_NAMES for n in names)


@dataclass(slots=True)
class BuiltProcess:
    """A process and what the package around it needs: its pool's lanes (model lanes, one
    participant each) and whether a user/manual task fell back on the ``user`` participant."""

    process: WorkflowProcess
    lanes: tuple[Lane, ...] = ()


class _Process:
    def __init__(self, element: etree._Element, defs: Defs) -> None:
        self.element = element
        self.defs = defs
        self.ctx = defs.ctx
        self.id = element.get("id") or ""
        self.sets: list[ActivitySet] = []
        self.lane_of: dict[str, str] = {}
        self.pool = defs.pool_of.get(self.id)
        self.lanes = tuple(lane for lane_set in kids(element, "laneSet")
                           for lane in self._lane_set(lane_set))
        self.lane_names: dict[str, str | None] = {}
        self.created: dict[str, DataField] = {}      # fields forms, outputs, parameters add
        self.reads: list[tuple[str, etree._Element, str]] = []
        # collection multi-instances' element variables, and the fields they may read
        self.collections: list[DataField] = []
        self.declared: dict[str, DataField | FormalParameter] = {}
        self.synthetic: set[str] = set()          # ids given to sequence flows without one
        for lane in self._all(self.lanes):
            self.lane_names[lane.id] = lane.name

    # -- lanes -----------------------------------------------------------------------------
    def _lane_set(self, lane_set: etree._Element) -> tuple[Lane, ...]:
        out: list[Lane] = []
        for lane in kids(lane_set, "lane"):
            lane_id = lane.get("id") or ""
            for ref in kids(lane, "flowNodeRef"):
                node = (ref.text or "").strip()
                if node:
                    self.lane_of[node] = lane_id     # nested lanes come later: innermost wins
            nested: tuple[Lane, ...] = ()
            for child_set in kids(lane, "childLaneSet"):
                nested += self._lane_set(child_set)
            out.append(Lane(id=lane_id, name=lane.get("name"), performers=(lane_id,),
                            lanes=nested, parent_pool=self.pool[0] if self.pool else None,
                            location=self.defs.loc(lane)))
        return tuple(out)

    @staticmethod
    def _all(lanes: tuple[Lane, ...]) -> Iterable[Lane]:
        stack = list(lanes)
        while stack:
            lane = stack.pop()
            yield lane
            stack.extend(lane.lanes)

    # -- performers ------------------------------------------------------------------------
    def performers(self, element: etree._Element, lane: str | None, manual: bool
                   ) -> tuple[str, ...]:
        """Resources the node's ``performer``/``humanPerformer``/``potentialOwner`` name; else
        its lane; else its pool; a user or manual task not in a lane or pool named for the
        user is performed by the user (participant ``user``)."""
        named: list[str] = []
        for role in ("performer", "humanPerformer", "potentialOwner", "resourceRole"):
            for assignment in kids(element, role):
                ref_element = first(assignment, "resourceRef")
                ref = (text_of(ref_element) or "").strip()
                if ":" in ref and ref not in self.defs.resources:
                    ref = ref.split(":", 1)[1]
                if ref and ref in self.defs.resources:
                    named.append(ref)
                elif ref:
                    self.ctx.error(ref_element, "unknown-reference",
                                   f"resourceRef {ref!r} names no bpmn:resource of this file",
                                   f"declare <bpmn:resource id=\"{ref}\"> or fix the reference")
                else:
                    self.defs.info(assignment, "performer-expression",
                                  f"the {local(assignment)} of {label(element)} is an "
                                  "expression, which opspec does not evaluate; its lane or pool "
                                  "performs it", "name a bpmn:resource with resourceRef")
        if named:
            return tuple(dict.fromkeys(named))
        if manual:
            pool_name = self.pool[1] if self.pool else None
            if not (is_user_name(lane, self.lane_names.get(lane or ""))
                    or (lane is None and is_user_name(self.pool[0] if self.pool else None,
                                                      pool_name))):
                self.defs.user_participant = True
                return ("user",)
        if lane:
            return (lane,)
        if self.pool:
            return (self.pool[0],)
        return ()

    # -- levels ----------------------------------------------------------------------------
    def level(self, container: etree._Element, inherited_lane: str | None
              ) -> tuple[tuple[Activity, ...], tuple[Transition, ...]]:
        """The activities and transitions of one level (the process, or a sub-process)."""
        nodes: list[etree._Element] = []
        flows: list[etree._Element] = []
        boundaries: list[etree._Element] = []
        hoist_event_sub_processes(container)
        for sub in container:
            if not isinstance(sub.tag, str):
                continue
            name = local(sub)
            if namespace(sub) != BPMN:
                self.ctx.warning(sub, "unknown-element",
                                 f"<{sub.prefix + ':' if sub.prefix else ''}{name}> is not a BPMN "
                                 f"element; opspec ignores it",
                                 "put vendor data inside bpmn:extensionElements")
            elif name in NODES or name in _SUB_PROCESSES:
                if name in _SUB_PROCESSES and sub.get("triggeredByEvent") == "true":
                    self.ctx.warning(sub, "unsupported-element",
                                     f"event sub-process {sub.get('id')!r}: opspec runs only "
                                     "those with one timer or message start event (in a level "
                                     "without triggered start events); it and everything in it "
                                     "are ignored",
                                     "model it as a boundary event on a sub-process, or as a "
                                     "workflow with a message or signal start event")
                    continue
                nodes.append(sub)
            elif name == "sequenceFlow":
                flows.append(sub)
            elif name == "boundaryEvent":
                boundaries.append(sub)
            elif name not in _QUIET:
                self.ctx.warning(sub, "unsupported-element",
                                 f"bpmn:{name} is not run by opspec; it is ignored",
                                 "docs/bpmn.md lists what opspec runs")
        ids = {node.get("id") or "" for node in nodes}
        boundary = read_boundaries(boundaries, ids, self.defs, self.where, self.plain)
        ids |= {b.id for b in boundary.activities}
        transitions = self.flows(flows, ids, nodes, boundary.skipped)
        transitions = decide_undecided(nodes, transitions,
                                       {f.get("id") or "": f for f in flows}, self.defs)
        transitions.extend(boundary.transitions)
        incoming: dict[str, int] = {}
        outgoing: dict[str, list[str]] = {}
        for transition in transitions:
            incoming[transition.target] = incoming.get(transition.target, 0) + 1
            outgoing.setdefault(transition.source, []).append(transition.id)
        conditional = {t.source for t in transitions
                       if t.condition.kind is ConditionKind.CONDITION}
        activities = [self.activity(node, inherited_lane, boundary, incoming, outgoing,
                                    conditional)
                      for node in nodes]
        activities.extend(boundary.activities)
        return tuple(activities), tuple(transitions)

    def flows(self, flows: list[etree._Element], ids: set[str], nodes: list[etree._Element],
              skipped: set[str]) -> list[Transition]:
        defaults = {node.get("default"): node for node in nodes if node.get("default")}
        out: list[Transition] = []
        for flow in flows:
            flow_id = flow.get("id") or ""
            ends = {}
            broken = False
            for attribute in ("sourceRef", "targetRef"):
                ref = (flow.get(attribute) or "").strip()
                ends[attribute] = ref
                if ref in skipped:
                    broken = True
                elif ref not in ids:
                    broken = True
                    detail = self.not_here(self.defs.by_id.get(ref), flow)
                    self.ctx.error(flow, "unknown-reference",
                                   f"sequence flow {flow_id!r}: {attribute} {ref!r} is no flow "
                                   f"node of {self.where(flow)}{detail}" if ref else
                                   f"sequence flow {flow_id!r} has no {attribute}",
                                   f"set {attribute} to the id of a flow node next to it "
                                   "(the flow is left out)")
            if broken:
                continue
            if not flow_id:
                # BPMN lets a sequence flow nothing refers to go without an id; the model
                # needs one per transition (splits order their flows by id)
                flow_id = self.flow_id(ends["sourceRef"], ends["targetRef"])
            condition = self.condition(flow, flow_id in defaults)
            out.append(Transition(id=flow_id, name=flow.get("name"), source=ends["sourceRef"],
                                  target=ends["targetRef"], condition=condition,
                                  assignments=assignments(flow, self.defs),
                                  description=text_of(first(flow, "documentation")),
                                  location=self.defs.loc(flow)))
        for flow_id, node in defaults.items():
            if flow_id not in {t.id for t in out} and flow_id not in skipped:
                where = self.defs.by_id.get(flow_id or "")
                if where is None or local(where) != "sequenceFlow":
                    self.ctx.error(node, "unknown-reference",
                                   f"{label(node)}: default {flow_id!r} is no sequence flow "
                                   "of this process", "name one of its outgoing sequence flows")
        return out

    def not_here(self, where: etree._Element | None, flow: etree._Element) -> str:
        """Why the element a flow's end names is no node of the flow's level, in words true
        of it: a flow node of another level, one of this level opspec left out (said at its
        line), or no flow node at all (a data object, a message)."""
        if where is None:
            return ""
        kind = local(where)
        if kind not in NODES and kind not in _SUB_PROCESSES and kind != "boundaryEvent":
            return f"; it is a bpmn:{kind}{self.defs.line(where)}, not a flow node"
        if where.getparent() is flow.getparent():
            return (f"; it is a bpmn:{kind}{self.defs.line(where)} that opspec leaves out "
                    "(its line says why)")
        return (f"; it is a bpmn:{kind}{self.defs.line(where)} of another process or "
                "sub-process (a sequence flow stays inside one)")

    def flow_id(self, source: str, target: str) -> str:
        """An id for a sequence flow written without one: ``source->target`` (``#2``… when
        two such flows join the same nodes), never an id of the file."""
        base = f"{source}->{target}"
        candidate, n = base, 1
        while candidate in self.defs.by_id or candidate in self.synthetic:
            n += 1
            candidate = f"{base}#{n}"
        self.synthetic.add(candidate)
        return candidate

    def where(self, element: etree._Element) -> str:
        parent = element.getparent()
        if parent is None or local(parent) == "process":
            return f"process {self.id!r}"
        return f"sub-process {parent.get('id')!r}"

    def condition(self, flow: etree._Element, default: bool) -> Condition:
        expression_element = first(flow, "conditionExpression")
        text = expression_text(expression_element)
        if default:
            if text is not None:
                self.ctx.warning(expression_element, "default-with-condition",
                                 f"sequence flow {flow.get('id')!r} is a default flow and has a "
                                 "condition; the condition is ignored (a default flow is taken "
                                 "when no other holds)", "remove the condition")
            return Condition(kind=ConditionKind.OTHERWISE)
        if text is None:
            return Condition()
        parsed = bpmn_condition(expression_element, text, self.defs,
                                         f"condition of sequence flow {flow.get('id')!r}")
        return Condition(kind=ConditionKind.CONDITION, text=text, expression=parsed)

    def plain(self, event: etree._Element, body: Event, host: str) -> Activity:
        lane = self.lane_of.get(event.get("id") or "") or self.lane_of.get(host)
        found, kept = directives(event, self.defs, ACTIVITY_DIRECTIVES, label(event))
        directive_values, coordination = activity_directives(event, self.ctx, found)
        return Activity(id=event.get("id") or "", name=event.get("name"),
                        description=text_of(first(event, "documentation")),
                        extended_attributes=kept, location=self.defs.loc(event), body=body,
                        performers=self.performers(event, lane, False), lane=lane,
                        directives=directive_values, coordination=coordination)

    # -- activities ------------------------------------------------------------------------
    def activity(self, element: etree._Element, inherited_lane: str | None, boundary: Boundaries,
                 incoming: dict[str, int], outgoing: dict[str, list[str]],
                 conditional: set[str]) -> Activity:
        node_id = element.get("id") or ""
        if not node_id:
            self.ctx.error(element, "missing-id", f"bpmn:{local(element)} has no id",
                           "give every flow node an id")
        name = local(element)
        lane = self.lane_of.get(node_id) or inherited_lane
        built_body: ActivityBody
        gateway: GatewayType | None = None
        extra: tuple[Assignment, ...] = ()
        sends: str | None = None
        manual = False
        if name in _SUB_PROCESSES:
            built_body = self.sub_process(element, lane)
        else:
            built = build_node(name, element, self.defs)
            built_body, gateway, extra = built.body, built.gateway, built.assignments
            sends, manual = built.sends, built.manual
        found, kept = directives(element, self.defs, ACTIVITY_DIRECTIVES, label(element),
                                 _ACTIVITY_STRUCTURE)
        self.message_directives(element, found, sends, built_body)
        directive_values, coordination = activity_directives(element, self.ctx, found)
        directive_values = self.simulated_duration(element, node_id, directive_values)
        data = activity_data(element, self.defs, label(element))
        for created in data.fields:
            self.created.setdefault(created.id, created)
        self.reads.extend((name, where, label(element)) for name, where in data.reads)
        start_mode = Mode.AUTOMATIC
        if name == "task" and isinstance(built_body, NoImplementation) and data.writes:
            # SpiffWorkflow's plain task waits for someone; one whose outputs nothing in the
            # file computes must: its performer supplies them when completing it
            manual, start_mode = True, Mode.MANUAL
            self.defs.info(element, "task-supplies-data",
                           f"{label(element)} writes {', '.join(data.writes)}, which "
                           "nothing in the file computes: it waits for its performer, whose "
                           "completion supplies the value", "docs/bpmn.md, Data")
        join = split = None
        if gateway is not None:
            join_condition = None
            join_text = None
            if gateway is GatewayType.COMPLEX:
                join_text = expression_text(first(element, "activationCondition"))
                join_condition = bpmn_condition(
                    first(element, "activationCondition"), join_text, self.defs,
                    "activationCondition")
            if incoming.get(node_id, 0) > 1:
                join_type = GatewayType.XOR if gateway is GatewayType.EVENT else gateway
                join = Join(type=join_type, condition=join_condition, condition_text=join_text)
            if outgoing.get(node_id):
                split = Split(type=gateway, transition_refs=self.order(element, outgoing[node_id]))
        elif node_id in conditional:
            # conditional sequence flows out of an activity: every one whose condition holds
            # is taken, the default flow when none does (BPMN 2.0 §13.2.1: an inclusive split)
            split = Split(type=GatewayType.OR,
                          transition_refs=self.order(element, outgoing[node_id]))
        return Activity(
            id=node_id, name=element.get("name"),
            description=text_of(first(element, "documentation")),
            extended_attributes=kept, location=self.defs.loc(element), body=built_body,
            performers=self.performers(element, lane, manual), lane=lane,
            start_mode=start_mode,
            deadlines=tuple(boundary.deadlines.get(node_id, ())),
            loop=read_loop(element, self.defs, self.declared, self.collections),
            join=join, split=split,
            directives=directive_values, coordination=coordination,
            assignments=assignments(element, self.defs) + extra + tuple(data.assignments),
            start_quantity=quantity(element, "startQuantity", self.ctx),
            completion_quantity=quantity(element, "completionQuantity", self.ctx))

    def simulated_duration(self, element: etree._Element, node_id: str,
                           given: ActivityDirectives) -> ActivityDirectives:
        """The task's duration from the file's BPSim or QBP parameters (:mod:`.simulation`)
        when it has no ``opspec:Duration`` of its own; its own wins, said in an info."""
        drawn = self.defs.durations.get(node_id)
        if drawn is None:
            return given
        source = self.defs.duration_source.get(node_id, "the file")
        if given.duration is not None:
            self.defs.info(element, "duration-given-twice",
                           f"{label(element)} has its own opspec:Duration, which wins "
                           f"over the {source} duration", "")
            return given
        return dataclasses.replace(given, duration=drawn)

    @staticmethod
    def order(element: etree._Element, flows: list[str]) -> tuple[str, ...]:
        """The order an exclusive gateway tests its flows in: its ``outgoing`` list (what
        modellers write, in drawing order), then any other flow in file order."""
        listed = [(ref.text or "").strip() for ref in kids(element, "outgoing")]
        ranked = [f for f in listed if f in flows]
        return tuple(dict.fromkeys([*ranked, *flows]))

    def message_directives(self, element: etree._Element, found: dict[str, Directive],
                           sends: str | None, body: object) -> None:
        """Message flows from and to an activity: it raises the message it sends when it
        completes (``opspec:Raises``) and waits for the message it receives before it starts
        (``opspec:StartTrigger``). Events and receive tasks carry their messages themselves."""
        node_id = element.get("id") or ""
        if isinstance(body, Event):
            return
        outgoing = [name for name, _ in self.defs.sends.get(node_id, [])]
        names = list(dict.fromkeys([*([sends] if sends else []), *outgoing]))
        if names and "Raises" not in found:
            flow = self.defs.sends.get(node_id, [(names[0], element)])[0][1]
            found["Raises"] = Directive("Raises", f"message:{names[0]}", None,
                                        self.defs.loc(flow))
            if len(names) > 1:
                self.ctx.warning(element, "several-messages",
                                 f"{label(element)} sends {len(names)} messages "
                                 f"({', '.join(names)}); opspec raises only {names[0]!r}",
                                 "send each message from its own send task or throw event")
        incoming = [name for name, _ in self.defs.receives.get(node_id, [])]
        if incoming and "StartTrigger" not in found:
            flow = self.defs.receives[node_id][0][1]
            found["StartTrigger"] = Directive("StartTrigger", f"message:{incoming[0]}", None,
                                              self.defs.loc(flow))

    def sub_process(self, element: etree._Element, lane: str | None) -> BlockActivity:
        set_id = element.get("id") or ""
        name = local(element)
        if name == "transaction":
            self.ctx.warning(element, "transaction",
                             f"transaction {set_id!r} runs as a plain sub-process: opspec has no "
                             "compensation or cancel", "see docs/bpmn.md")
        activities, transitions = self.level(element, lane)
        ad_hoc = name == "adHocSubProcess"
        ordering = (element.get("ordering") or "Parallel").strip().lower()
        completion_text = expression_text(first(element, "completionCondition")) if ad_hoc else None
        self.sets.append(ActivitySet(
            id=set_id, name=element.get("name"), activities=activities, transitions=transitions,
            ad_hoc=ad_hoc, ad_hoc_sequential=ad_hoc and ordering == "sequential",
            completion_condition_text=completion_text,
            completion_condition=bpmn_condition(
                first(element, "completionCondition"), completion_text, self.defs,
                "completionCondition"),
            location=self.defs.loc(element)))
        return BlockActivity(activity_set=set_id)

    # -- the process -----------------------------------------------------------------------
    def build(self) -> BuiltProcess:
        element = self.element
        found, kept = directives(element, self.defs, PROCESS_DIRECTIVES,
                                 f"process {self.id!r}", ("DataField", "FormalParameter"))
        fields = [data_field(sub, self.defs) for sub in opspec_named(element, "DataField")]
        bpmn_fields, bpmn_formals = process_fields(element, self.defs)
        given = {f.id for f in fields}
        fields.extend(f for f in bpmn_fields if f.id not in given)
        formals = tuple(formal_parameter(sub, self.defs)
                        for sub in opspec_named(element, "FormalParameter"))
        given = {f.id for f in formals}
        formals += tuple(f for f in bpmn_formals if f.id not in given)
        self.declared = {f.id: f for f in fields}
        self.declared.update((f.id, f) for f in formals)
        activities, transitions = self.level(element, None)
        declared = {f.id for f in (*fields, *formals)} | self.defs.package_fields
        fields.extend(f for name, f in self.created.items() if name not in declared)
        declared |= {f.id for f in fields}
        for element_field in self.collections:     # one field for each name, however many use it
            if element_field.id not in declared:
                declared.add(element_field.id)
                fields.append(element_field)
        process = WorkflowProcess(
            id=self.id, name=element.get("name"),
            description=text_of(first(element, "documentation")),
            extended_attributes=kept, location=self.defs.loc(element),
            access_level="PUBLIC", data_fields=tuple(fields), formal_parameters=formals,
            activities=activities, transitions=transitions, activity_sets=tuple(self.sets),
            directives=self.arrivals(process_directives(element, self.ctx, found)))
        process = _with_script_fields(process, element, self.defs)
        self.check_reads(process)
        return BuiltProcess(process, self.lanes)

    def arrivals(self, given: ProcessDirectives) -> ProcessDirectives:
        """The process's arrivals from the file's BPSim or QBP parameters, unless its own
        ``opspec:Arrival`` or ``opspec:StartTrigger`` says how it starts."""
        found = self.defs.arrivals.get(self.id)
        if found is None:
            return given
        distribution, count, source = found
        if given.arrival is not None or given.start_trigger is not None:
            own = "opspec:Arrival" if given.arrival is not None else "opspec:StartTrigger"
            self.defs.info(self.element, "arrivals-given-twice",
                           f"process {self.id!r} has its own {own}, which wins over the "
                           f"{source} arrivals", "")
            return given
        return dataclasses.replace(given, arrival=distribution, arrival_count=count)

    def check_reads(self, process: WorkflowProcess) -> None:
        """A task's ``dataInput`` without an association takes the process's variable of its
        name (as SpiffWorkflow does): something must declare or set it."""
        known = {f.id for f in (*process.data_fields, *process.formal_parameters)}
        known |= self.defs.package_fields
        for name, where, shown in self.reads:
            if name not in known:
                self.ctx.error(where, "undefined-data-field",
                               f"{shown} takes its dataInput {name!r} from the process, but "
                               f"nothing in process {self.id!r} declares or sets {name!r}",
                               "declare a bpmn:dataObject or bpmn:property with that id, set it "
                               "in a script task or a form field, or feed the input with a "
                               "bpmn:dataInputAssociation")


def _with_script_fields(process: WorkflowProcess, element: etree._Element, defs: Defs
                        ) -> WorkflowProcess:
    """BPMN engines create a variable when a script first sets it: a name a script task
    assigns that no data field or formal parameter declares becomes a data field of the
    process, starting without a value (typed by the first value assigned to it)."""
    declared = {f.id for f in (*process.data_fields, *process.formal_parameters)}
    declared |= defs.package_fields
    created: dict[str, Assignment] = {}
    for activity in process.all_activities():
        if not (isinstance(activity.body, Task) and activity.body.kind is TaskKind.SCRIPT):
            continue
        for assignment in activity.assignments:
            root = assignment.target.split(".", 1)[0]
            if root and root not in declared and root not in created:
                created[root] = assignment
    if not created:
        return process
    from dataclasses import replace

    defs.info(element, "script-variables",
                  f"process {process.id!r}: the variables its script tasks set "
                  f"({', '.join(created)}) become data fields, starting without a value",
                  "declare them with opspec:DataField to give them an initial value")
    extra = tuple(DataField(id=name, type=BasicType(kind=literal_kind(a.expression)),
                            location=a.location) for name, a in created.items())
    return replace(process, data_fields=process.data_fields + extra)


def build_process(element: etree._Element, defs: Defs) -> BuiltProcess:
    """The :class:`WorkflowProcess` of a ``bpmn:process`` element and its pool's lanes."""
    return _Process(element, defs).build()

