"""``opspec show``'s text format: a compact, indented description of a package (its header,
participants, lanes and every process with its directives, data, activities and transitions)."""

from __future__ import annotations

from opspec.model.activities import (
    Activity,
    BlockActivity,
    Event,
    Reference,
    Route,
    SubFlow,
    Task,
)
from opspec.model.data import BasicType, DataField, DataType, DeclaredType, FormalParameter
from opspec.model.package import Package
from opspec.model.process import ConditionKind, Transition, WorkflowProcess
from opspec.model.resources import Lane, ParticipantType
from opspec.model.sisarl import (
    ActivityDirectives,
    CoordinationBuiltIn,
    CoordinationKind,
    ProcessDirectives,
    TriggerRef,
    WorkflowMode,
)

__all__ = ["describe_package"]


def describe_package(package: Package, *, process: str | None = None) -> str:
    """The ``text`` format: a compact, indented description of ``package``."""
    from opspec.clock import span

    out: list[str] = []
    title = f"Package {package.id!r}" + (f" {package.name!r}" if package.name else "")
    out.append(f"{title}  ({package.source_format}"
               + (f", {package.source}" if package.source else "") + ")")
    header = package.header
    facts = [f"vendor {header.vendor}" if header.vendor else "",
             f"conformance {package.conformance_class}" if package.conformance_class else "",
             f"external packages: {', '.join(e.href or e.id for e in package.external_packages)}"
             if package.external_packages else ""]
    if any(facts):
        out.append("  " + "; ".join(f for f in facts if f))
    if package.participants:
        out.append("Participants:")
        out.extend(f"  {p.id:<20} {_role(p.type):<8} {p.name or ''}".rstrip()
                   for p in package.participants)
    if package.applications:
        out.append("Applications: " + ", ".join(a.id for a in package.applications))
    if package.data_fields:
        out.append("Package data: " + "; ".join(_field(f) for f in package.data_fields))
    if package.pools:
        out.append("Pools:")
        for pool in package.pools:
            owner = f" (process {pool.process})" if pool.process else ""
            out.append(f"  {pool.id} {pool.name or ''}{owner}".rstrip())
            _lanes(out, pool.lanes, "    ")
    if package.modes:
        out.append("Modes: " + "; ".join(_mode(m, package) for m in package.modes))
    if package.run_length is not None:
        out.append(f"Run length: {span(package.run_length)}")
    if package.message_ttl is not None:
        out.append(f"Message TTL: {span(package.message_ttl)} (a message nobody waits for)")
    if package.metrics:
        out.append("Metrics: " + ", ".join(f"{m.name} ({m.kind.value})" for m in package.metrics))
    for proc in package.processes:
        if process is None or proc.id == process:
            out.append("")
            _process(out, proc, package)
    return "\n".join(out) + "\n"


def _mode(mode: WorkflowMode, package: Package) -> str:
    """A mode and the workflows it runs: those it lists and those whose ``opspec:Mode`` names
    it, as the engine gathers them (most specs only use the latter)."""
    workflows = dict.fromkeys((*mode.workflows, *(p.id for p in package.processes
                                                  if p.directives.mode == mode.id)))
    text = mode.id + (" (initial)" if mode.initial else "")
    text += f": {', '.join(workflows)}" if workflows else ": no workflow"
    return text + (f", loads {mode.source}" if mode.source else "")


def _role(kind: ParticipantType) -> str:
    return {ParticipantType.HUMAN: "human", ParticipantType.SYSTEM: "system"}.get(
        kind, kind.value.lower().replace("_", " "))


def _lanes(out: list[str], lanes: tuple[Lane, ...], indent: str) -> None:
    for lane in lanes:
        who = f" [{', '.join(lane.performers)}]" if lane.performers else ""
        out.append(f"{indent}lane {lane.id} {lane.name or ''}{who}".rstrip())
        _lanes(out, lane.lanes, indent + "  ")


def _type(data_type: DataType) -> str:
    if isinstance(data_type, BasicType):
        return data_type.kind.value
    if isinstance(data_type, DeclaredType):
        return data_type.ref
    return type(data_type).__name__.removesuffix("Type").lower()


def _field(field: DataField) -> str:
    initial = f" = {field.initial_value}" if field.initial_value is not None else ""
    return f"{field.id}: {_type(field.type)}{initial}"


def _parameter(parameter: FormalParameter) -> str:
    return f"{parameter.mode.value} {parameter.id}: {_type(parameter.type)}"


def _trigger(trigger: TriggerRef) -> str:
    from opspec.clock import span, time_of_day

    if trigger.name:
        return f"{trigger.kind}:{trigger.name}"
    if trigger.kind == "rule" and trigger.condition is not None:
        from opspec.model.expression_text import to_text

        return f"rule {to_text(trigger.condition)}"
    text = trigger.kind
    if trigger.at:
        text += " at " + ", ".join(time_of_day(t) for t in trigger.at)
    if trigger.every is not None:
        text += f" every {span(trigger.every)}"
    return text


def _directives(directives: ProcessDirectives) -> str:
    parts = []
    if directives.period is not None:
        parts.append(f"period {directives.period:g} s")
    if directives.priority is not None:
        parts.append(f"priority {directives.priority}")
    if directives.deadline is not None:
        parts.append(f"latency bound {directives.deadline:g} s")
    if directives.start_trigger is not None:
        parts.append(f"starts on {_trigger(directives.start_trigger)}")
    if directives.end_trigger is not None:
        parts.append(f"ends on {_trigger(directives.end_trigger)}")
    if directives.auto_start is not None:
        parts.append("auto-start" if directives.auto_start else "no auto-start")
    if directives.arrival is not None:
        from opspec.xpdl.sisarl_write import distribution_text

        count = ("" if directives.arrival_count is None
                 else f", {directives.arrival_count} in all")
        parts.append(f"arrivals every {distribution_text(directives.arrival)}{count}")
    if directives.lane:
        parts.append(f"lane {directives.lane}")
    if directives.mode:
        parts.append(f"mode {directives.mode}")
    return ", ".join(parts)


def _process(out: list[str], process: WorkflowProcess, package: Package) -> None:
    title = f"Process {process.id!r}" + (f" {process.name!r}" if process.name else "")
    out.append(title)
    directives = _directives(process.directives)
    if directives:
        out.append(f"  directives: {directives}")
    if process.formal_parameters:
        out.append("  parameters: " + "; ".join(_parameter(p) for p in process.formal_parameters))
    if process.data_fields:
        out.append("  data: " + "; ".join(_field(f) for f in process.data_fields))
    if process.participants:
        out.append("  participants: " + ", ".join(
            f"{p.id} ({_role(p.type)})" for p in process.participants))
    _activities(out, process, package, process.activities, process.transitions, "  ")
    for aset in process.activity_sets:
        out.append(f"  activity set {aset.id!r}" + (f" {aset.name!r}" if aset.name else ""))
        _activities(out, process, package, aset.activities, aset.transitions, "    ")


def _activities(out: list[str], process: WorkflowProcess, package: Package,
                activities: tuple[Activity, ...], transitions: tuple[Transition, ...],
                indent: str) -> None:
    if activities:
        out.append(f"{indent}activities:")
        width = min(max(len(a.id) for a in activities), 24)
        for activity in activities:
            out.append(f"{indent}  {activity.id:<{width}}  {_activity(activity, process, package)}")
    if transitions:
        out.append(f"{indent}transitions:")
        width = min(max(len(t.id) for t in transitions), 24)
        for transition in transitions:
            out.append(f"{indent}  {transition.id:<{width}}  {transition.source} -> "
                       f"{transition.target}{_condition(transition)}")


def _performer(name: str, process: WorkflowProcess, package: Package) -> str:
    participant = package.participant(name) or next(
        (p for p in process.participants if p.id == name), None)
    if participant is None:
        return name
    return f"{name} ({_role(participant.type)})"


def _activity(activity: Activity, process: WorkflowProcess, package: Package) -> str:
    parts = [_kind(activity)]
    if activity.name and activity.name != activity.id:
        parts.insert(0, repr(activity.name))
    if activity.performers:
        parts.append("by " + ", ".join(_performer(p, process, package)
                                       for p in activity.performers))
    parts.append("manual" if package.is_manual_work(activity, process) else "automatic")
    if activity.join is not None:
        parts.append(f"join {activity.join.type.value}")
    if activity.split is not None:
        parts.append(f"split {activity.split.type.value}")
    for deadline in activity.deadlines:
        raised = f" -> {deadline.exception_name}" if deadline.exception_name else ""
        parts.append(f"deadline {deadline.duration_text}{raised} ({deadline.execution.value})")
    if activity.loop is not None:
        parts.append(f"loop {activity.loop.kind.value}"
                     + (f" while {activity.loop.condition_text}"
                        if activity.loop.condition_text else ""))
    if activity.coordination is not None:
        parts.append(_built_in(activity.coordination))
    parts.extend(_activity_directives(activity.directives))
    return ", ".join(parts)


def _built_in(built_in: CoordinationBuiltIn) -> str:
    """``built-in arbiter motor_cmd <- escape_cmd, avoid_cmd``, ``built-in push distance ->
    channel range``, ``built-in mode-change to dock``: what it reads and writes."""
    text = f"built-in {built_in.kind.value}"
    inputs = ", ".join(built_in.inputs)
    if built_in.kind is CoordinationKind.PUSH_DATA:
        return f"{text} {inputs} -> channel {built_in.channel}"
    if built_in.kind is CoordinationKind.PULL_DATA:
        return f"{text} {built_in.output} <- channel {built_in.channel}"
    if built_in.kind is CoordinationKind.MODE_CHANGE:
        return f"{text} to {built_in.target_mode}"
    text += f" {built_in.output} <- {inputs}"
    if built_in.weights:
        text += f" (weights {', '.join(f'{w:g}' for w in built_in.weights)})"
    if built_in.options:
        text += f" (options {', '.join(built_in.options)})"
    return text


def _activity_directives(directives: ActivityDirectives) -> list[str]:
    """What the SISARL directives of an activity add: when it starts and ends, what it raises
    (the messages that link the device's workflows to the user's), its time and CPU."""
    from opspec.xpdl.sisarl_write import distribution_text

    parts = []
    if directives.start_trigger is not None:
        parts.append(f"starts on {_trigger(directives.start_trigger)}")
    if directives.end_trigger is not None:
        parts.append(f"ends on {_trigger(directives.end_trigger)}")
    if directives.raises is not None:
        parts.append(f"raises {_trigger(directives.raises)}")
    if directives.duration is not None:
        parts.append(f"takes {distribution_text(directives.duration)}")
    if directives.cpu_demand is not None:
        parts.append(f"cpu {directives.cpu_demand:g} s")
    elif directives.cpu_distribution is not None:
        parts.append(f"cpu {distribution_text(directives.cpu_distribution)}")
    if directives.priority_increment:
        parts.append(f"priority +{directives.priority_increment}")
    return parts


def _kind(activity: Activity) -> str:
    body = activity.body
    if isinstance(body, Task):
        apps = ", ".join(a.application for a in body.applications)
        return f"{body.kind.value} task" + (f" [{apps}]" if apps else "")
    if isinstance(body, SubFlow):
        return f"subflow -> {body.process} ({body.execution.value.lower()})"
    if isinstance(body, Route):
        return f"route {body.gateway.value}"
    if isinstance(body, BlockActivity):
        return f"block -> set {body.activity_set}"
    if isinstance(body, Event):
        trigger = body.trigger.kind.value
        name = f" {body.trigger.name}" if body.trigger.name else ""
        return f"{body.position.value} event ({trigger}{name})"
    if isinstance(body, Reference):
        return f"reference -> {body.activity}"
    return "activity"


def _condition(transition: Transition) -> str:
    condition = transition.condition
    if condition.kind is ConditionKind.CONDITION and condition.text:
        return f"  [if {' '.join(condition.text.split())}]"
    if condition.kind is ConditionKind.OTHERWISE:
        return "  [otherwise]"
    if condition.kind is ConditionKind.EXCEPTION:
        name = condition.exception_name or (condition.text or "").strip()
        return f"  [exception {name}]" if name else "  [exception]"
    if condition.kind is ConditionKind.DEFAULTEXCEPTION:
        return "  [default exception]"
    return ""
