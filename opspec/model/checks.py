"""Structural checks on the immutable model: what a reader cannot see element by element.

:func:`check_package` looks at a whole :class:`~opspec.model.package.Package` (built by the XPDL
front end or in plain Python) and returns every problem as a
:class:`~opspec.errors.Diagnostic`: a stable kebab-case ``code``, the element's
``path:line``, a message naming the ids involved (activity ids are scoped per process and per
activity set, so the message says which) and a fix hint. Errors are problems that make a run
impossible or wrong; warnings are suspicious constructions a run survives. The codes are listed
in ``docs/validation.md``.

The checks never raise for a bad model and never import the XPDL front end (no lxml): the
names an expression reads are found by walking the expression tree here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import MappingProxyType

from opspec.errors import Diagnostic
from opspec.model.activities import (
    Activity,
    BlockActivity,
    Deadline,
    Event,
    Execution,
    GatewayType,
    LoopKind,
    Reference,
    Route,
)
from opspec.model.bulk import gc_paused
from opspec.model.checks_refs import RefChecks
from opspec.model.checks_support import Reporter, quote_list, where
from opspec.model.common import Element
from opspec.model.expressions import Literal
from opspec.model.graph import EXCEPTION_KINDS, FlowGraph, and_join_deadlocks, attached_to
from opspec.model.package import Package
from opspec.model.process import (
    ActivitySet,
    Condition,
    ConditionKind,
    Transition,
    WorkflowProcess,
)
from opspec.model.unpassed_parameters import unpassed_parameters

__all__ = ["check_package", "check_process"]

_NO_PACKAGES: Mapping[str, Package] = MappingProxyType({})


def check_package(
    package: Package, *, packages: Mapping[str, Package] = _NO_PACKAGES
) -> list[Diagnostic]:
    """Every structural problem of ``package``, in a stable order (package-level checks first,
    then each process in file order).

    ``packages`` maps Package Id to the other packages loaded with it (external packages and
    subflow targets, as :func:`opspec.xpdl.load_package` returns them); participants,
    applications and subflow targets found there count as defined. Never raises.
    """
    with gc_paused():       # a big package: no full collections while it is walked
        return _check_package(package, packages)


def _check_package(package: Package, packages: Mapping[str, Package]) -> list[Diagnostic]:
    report = Reporter(package)
    refs = RefChecks(package, packages, report)
    report.duplicates(package.processes, "process", f"package {package.id!r}")
    report.duplicates(package.participants, "participant", f"package {package.id!r}")
    report.duplicates(package.applications, "application", f"package {package.id!r}")
    report.duplicates(package.data_fields, "data field", f"package {package.id!r}")
    report.duplicates(package.type_declarations, "type declaration", f"package {package.id!r}")
    report.duplicates(package.pools, "pool", f"package {package.id!r}")
    refs.pools()
    refs.sisarl()
    for process in package.processes:
        _check_process(process, package, refs, report)
    unpassed_parameters(package, packages, report)
    from opspec.model.checks_triggers import trigger_name_diagnostics

    return [*report.diagnostics, *trigger_name_diagnostics(package, packages)]


def check_process(
    process: WorkflowProcess, package: Package, *,
    packages: Mapping[str, Package] = _NO_PACKAGES,
) -> list[Diagnostic]:
    """The checks of one process of ``package`` only (no package-level checks)."""
    report = Reporter(package)
    _check_process(process, package, RefChecks(package, packages, report), report)
    return report.diagnostics


def _parameter_fields(process: WorkflowProcess, report: Reporter, scope: str) -> None:
    """A DataField with the Id of a FormalParameter of the same process is that parameter
    (one variable, as the WfMC sample engines and Shark treat them): a warning, not an
    error. The data field's initial value is the default, the caller's value replaces it."""
    formals = {f.id: f for f in process.formal_parameters if f.id}
    for data_field in process.data_fields:
        formal = formals.get(data_field.id)
        if formal is None:
            continue
        line = formal.location.line if formal.location is not None else None
        at = f" (line {line})" if line is not None else ""
        report.warning(
            data_field, "parameter-data-field",
            f"data field {data_field.id!r} has the Id of formal parameter {formal.id!r}{at} "
            f"of {scope}: opspec treats them as one variable (the data field's initial value "
            "until the caller's value replaces it), as the WfMC sample engines do",
            "delete the data field, or rename it if it is meant to be a separate variable")


def _check_process(process: WorkflowProcess, package: Package, refs: RefChecks,
                   report: Reporter) -> None:
    scope = where(process, None)
    report.duplicates(process.participants, "participant", scope)
    report.duplicates(process.applications, "application", scope)
    report.duplicates(process.formal_parameters, "formal parameter", scope)
    report.duplicates(process.data_fields, "data field", scope)
    _parameter_fields(process, report, scope)
    report.duplicates(process.activity_sets, "activity set", scope)
    refs.process(process)
    used_sets: set[str] = set()
    for activity in process.all_activities():
        if isinstance(activity.body, BlockActivity):
            used_sets.add(activity.body.activity_set)
    levels: list[tuple[ActivitySet | None, tuple[Activity, ...]]] = [(None, process.activities)]
    levels.extend((s, s.activities) for s in process.activity_sets)
    graphs = {
        (s.id if s is not None else None): FlowGraph.of(
            acts, process.transitions if s is None else s.transitions)
        for s, acts in levels
    }
    starts_by_block: dict[str, str | None] = {}
    for activity in process.all_activities():
        body = activity.body
        if isinstance(body, BlockActivity) and body.activity_set not in starts_by_block:
            starts_by_block[body.activity_set] = body.start_activity
    for aset, _ in levels:
        graph = graphs[aset.id if aset is not None else None]
        if aset is not None and aset.id not in used_sets:
            report.warning(
                aset, "unused-activity-set",
                f"activity set {aset.id!r} of process {process.id!r} is used by no "
                "BlockActivity, so its activities never run",
                "refer to it from a BlockActivity (ActivitySetId) or delete it")
        _check_level(process, aset, graph, package, refs, report,
                     starts_by_block.get(aset.id) if aset is not None else None)


def _check_level(process: WorkflowProcess, aset: ActivitySet | None, graph: FlowGraph,
                 package: Package, refs: RefChecks, report: Reporter,
                 start_activity: str | None) -> None:
    scope = where(process, aset)
    report.duplicates(graph.activities, "activity", scope)
    transitions = process.transitions if aset is None else aset.transitions
    report.duplicates(transitions, "transition", scope)
    _dangling(process, aset, graph, report)
    for activity in graph.activities:
        refs.activity(process, aset, activity)
        _activity_structure(process, aset, graph, activity, report)
    for transition in transitions:
        refs.transition(process, aset, transition)
    _flow(process, aset, graph, package, report, start_activity)


def _dangling(process: WorkflowProcess, aset: ActivitySet | None, graph: FlowGraph,
              report: Reporter) -> None:
    container = where(process, aset)
    for transition in graph.dangling:
        for end, verb in ((transition.source, "comes from"), (transition.target, "points to")):
            if not end or end in graph.by_id:
                continue      # an empty end was reported by the reader (missing From/To)
            elsewhere = _find_elsewhere(report.package, end)
            attribute = "To" if verb == "points to" else "From"
            if elsewhere:
                hint = (f"{end!r} is an activity of {elsewhere}: set {attribute} to an activity "
                        f"of {container}, or move the transition there")
            else:
                hint = f"set {attribute} to the Id of an activity of {container}"
            report.error(
                transition, "dangling-transition",
                f"Transition {transition.id!r} {verb} activity {end!r}, which is not in "
                f"{container} (activity ids are scoped per process)", hint)


def _find_elsewhere(package: Package, activity_id: str) -> str | None:
    for process in package.processes:
        if process.activity(activity_id) is not None:
            return where(process, None)
        for aset in process.activity_sets:
            if aset.activity(activity_id) is not None:
                return where(process, aset)
    return None


def _activity_structure(process: WorkflowProcess, aset: ActivitySet | None, graph: FlowGraph,
                        activity: Activity, report: Reporter) -> None:
    """Splits, conditions, OTHERWISE, deadlines and references inside one level."""
    scope = where(process, aset)
    outgoing = graph.outgoing.get(activity.id, ())
    if graph.by_id.get(activity.id) is not activity:
        return      # a duplicate id: reported, and its transitions belong to the first one
    body = activity.body
    if isinstance(body, Reference) and body.activity not in graph.by_id:
        report.error(activity, "undefined-activity-reference",
                     f"activity {activity.id!r} in {scope} is a Reference to activity "
                     f"{body.activity!r}, which is not in {scope}",
                     "set ActivityId to an activity of the same process level")
    host = attached_to(activity)
    if host is not None and host not in graph.by_id:
        report.error(activity, "undefined-attached-activity",
                     f"event {activity.id!r} in {scope} is attached to activity {host!r}, "
                     f"which is not in {scope}", "fix Target/ActivityId of the trigger")
    if activity.split is not None and activity.split.transition_refs:
        by_id = graph.transition_by_id
        for ref in activity.split.transition_refs:
            transition = by_id.get(ref)
            if transition is None:
                report.error(activity, "undefined-transition-ref",
                             f"the split of activity {activity.id!r} in {scope} lists "
                             f"TransitionRef {ref!r}, which is not a transition of {scope}",
                             "list the Ids of the activity's outgoing transitions")
            elif transition.source != activity.id:
                report.error(activity, "undefined-transition-ref",
                             f"the split of activity {activity.id!r} in {scope} lists "
                             f"TransitionRef {ref!r}, which leaves activity "
                             f"{transition.source!r}, not {activity.id!r}",
                             "list the Ids of the activity's outgoing transitions")
    otherwise = [t for t in outgoing if t.condition.kind is ConditionKind.OTHERWISE]
    if len(otherwise) > 1:
        report.error(otherwise[1], "duplicate-otherwise",
                     f"activity {activity.id!r} in {scope} has {len(otherwise)} OTHERWISE "
                     f"transitions ({quote_list(t.id for t in otherwise)}); only one can be the "
                     "default", "keep one OTHERWISE transition and give the others conditions")
    if activity.split is None and not isinstance(body, Route | Event):
        for transition in outgoing:
            if transition.condition.kind is ConditionKind.CONDITION and (
                    transition.condition.expression is not None or transition.condition.text):
                report.warning(
                    transition, "condition-without-split",
                    f"Transition {transition.id!r} out of activity {activity.id!r} in {scope} "
                    f"has a condition, but {activity.id!r} declares no split: opspec takes "
                    "every outgoing transition whose condition holds (BPMN conditional "
                    "sequence flows, an inclusive split), the OTHERWISE one when none holds, "
                    "and ends that path when none can be taken",
                    f"declare <Split Type=\"XOR\"> on {activity.id!r} if only the first "
                    "transition that holds should be taken")
                break
    join = activity.join
    if (join is not None and join.type is GatewayType.COMPLEX
            and len(graph.incoming.get(activity.id, ())) > 1 and join.condition is None):
        text = join.condition_text
        report.error(activity, "complex-join-without-condition",
                     f"activity {activity.id!r} in {scope} is a Complex join "
                     + (f"whose IncomingCondition {text!r} cannot be evaluated"
                        if text else "without an IncomingCondition") +
                     ", so opspec cannot tell when it fires",
                     'give the Route an IncomingCondition over activationCount (e.g. '
                     'IncomingCondition="activationCount >= 2" for a 2-out-of-M join, '
                     '"activationCount >= 1" for a discriminator), or use an AND/OR join')
    loop = activity.loop
    if (loop is not None and loop.kind is LoopKind.MULTI_INSTANCE and loop.condition is None):
        report.error(activity, "multi-instance-without-count",
                     f"activity {activity.id!r} in {scope} is a multi-instance loop "
                     + (f"whose MI_Condition {loop.condition_text!r} cannot be evaluated"
                        if loop.condition_text else "without an MI_Condition") +
                     ", so the number of instances is unknown",
                     'write MI_Condition="N" (an integer expression over data fields)')
    _unconditional_xor(scope, graph, activity, report)
    _deadlines(scope, activity, outgoing, report)


def _unconditional_xor(scope: str, graph: FlowGraph, activity: Activity,
                       report: Reporter) -> None:
    if activity.split is None or activity.split.type is not GatewayType.XOR:
        return
    if isinstance(activity.body, Route) and activity.body.gateway is GatewayType.EVENT:
        return       # event-based: the first event to arrive picks the branch
    branches = [t for t in graph.outgoing.get(activity.id, ())
                if t.condition.kind is ConditionKind.NONE]
    if len(branches) < 2:
        return
    if all(t.probability is not None for t in branches):
        return       # drawn with branch probabilities (said where the reader set them)
    targets = [graph.by_id[t.target] for t in branches]
    if all(t.is_manual or t.performers for t in targets):
        return       # a deferred choice: the performer picks the branch (engine semantics)
    if all(t.condition.text for t in branches):
        return       # labelled branches (ScriptGrammar="Text"): the performer picks one
    report.warning(
        activity, "unconditional-xor-branches",
        f"XOR split {activity.id!r} in {scope} has {len(branches)} unconditional transitions "
        f"({quote_list(t.id for t in branches)}); only the first in TransitionRefs order is "
        "ever taken", "give the branches conditions (and one OTHERWISE), or use an AND split")


def _deadlines(scope: str, activity: Activity, outgoing: Sequence[Transition],
               report: Reporter) -> None:
    if not activity.deadlines:
        return
    handlers = [t for t in outgoing if t.condition.kind in EXCEPTION_KINDS]
    default = any(t.condition.kind is ConditionKind.DEFAULTEXCEPTION for t in handlers)
    for deadline in activity.deadlines:
        if not _can_expire(deadline):
            continue         # no duration (the reader reported it): it never fires
        name = deadline.exception_name
        handled = default or any(
            t.condition.kind is ConditionKind.EXCEPTION and (
                _exception_of(t.condition) in (None, name)) for t in handlers)
        if handled:
            continue
        caught = f"exception {name!r}" if name else "its exception"
        if deadline.execution is Execution.ASYNCHR:
            # an asynchronous deadline lets the activity run on: unhandled, it does nothing
            report.warning(
                deadline.location or activity.location or activity, "unhandled-deadline",
                f"activity {activity.id!r} in {scope} has an asynchronous deadline "
                f"({deadline.duration_text}) but no EXCEPTION or DEFAULTEXCEPTION transition "
                f"catches {caught}: when it expires the activity runs on and nothing else "
                "happens (an engine's own handler, e.g. a Bonita deadline hook, is not run)",
                "add a transition out of the activity with <Condition Type=\"EXCEPTION\">"
                f"{name or ''}</Condition> for the path to start beside it, or delete the "
                "deadline")
            continue
        report.error(
            deadline.location or activity.location or activity, "deadline-without-exception-path",
            f"activity {activity.id!r} in {scope} has a deadline ({deadline.duration_text}) but "
            f"no EXCEPTION or DEFAULTEXCEPTION transition catches {caught}: when it expires "
            "the instance aborts",
            "add a transition out of the activity with <Condition Type=\"EXCEPTION\">"
            f"{name or ''}</Condition> (or DEFAULTEXCEPTION)")


def _can_expire(deadline: Deadline) -> bool:
    if isinstance(deadline.duration, Literal):
        return deadline.duration.value is not None
    return deadline.duration is not None or deadline.duration_text.strip() not in ("", "None")


def _exception_of(condition: Condition) -> str | None:
    """The exception an EXCEPTION transition catches (``None``: any), as the engine reads it."""
    if condition.exception_name is not None:
        return condition.exception_name
    return (condition.text or "").strip() or None


def _flow(process: WorkflowProcess, aset: ActivitySet | None, graph: FlowGraph,
          package: Package, report: Reporter, start_activity: str | None) -> None:
    """Starts, reachability, AND-join deadlocks and conformance-class cycles of one level."""
    if not graph.by_id:
        return
    scope = where(process, aset)
    starts = graph.starts(start_activity)
    owner: Element = aset if aset is not None else process
    if start_activity is not None and start_activity not in graph.by_id:
        report.error(owner, "undefined-start-activity",
                     f"a BlockActivity starts {scope} at activity {start_activity!r}, which is "
                     f"not in it", "fix StartActivityId, or remove it to start where no "
                     "transition comes in")
    if not starts:
        report.error(owner, "no-start-activity",
                     f"{scope} has no start activity: every activity has an incoming "
                     "transition and there is no start event",
                     "add a start event (or an activity without incoming transitions) in "
                     "front of the cycle, or mark where it starts (XPDL: "
                     "StartActivity=\"true\")")
        return
    reached = graph.reachable(starts)
    for activity in graph.by_id.values():
        if activity.id not in reached:
            report.warning(
                activity, "unreachable-activity",
                f"activity {activity.id!r} in {scope} is unreachable from its start "
                f"({quote_list(starts)}), so it never runs",
                "connect it with a transition from a reachable activity, or delete it")
    for found in and_join_deadlocks(graph, starts):
        join = graph.by_id[found.join]
        hint = f"make {found.join!r} an XOR join, or {found.split!r} an AND split"
        if found.certain:
            report.error(
                join, "and-join-deadlock",
                f"AND-join {found.join!r} in {scope} is fed only by exclusive split "
                f"{found.split!r}: taking its transition {found.branch!r} brings a token on "
                f"{quote_list(found.arrives)} but never on {quote_list(found.missing)}, so the "
                "join waits forever (deadlock)", hint)
        else:
            report.warning(
                join, "possible-and-join-deadlock",
                f"AND-join {found.join!r} in {scope} is fed only by exclusive split "
                f"{found.split!r}: after its transition {found.branch!r}, tokens can reach "
                f"{quote_list(found.arrives)} (through further conditions) but never "
                f"{quote_list(found.missing)}; unless those conditions exclude that path, the "
                "join waits forever", hint)
    conformance = (package.conformance_class or "").upper()
    if conformance in ("LOOP_BLOCKED", "FULL_BLOCKED"):
        cycle = graph.find_cycle()
        if cycle is not None:
            report.warning(
                graph.by_id[cycle[0]], "conformance-cycle",
                f"package {package.id!r} declares graph conformance {conformance}, which "
                f"forbids cycles, but {scope} has the cycle {' -> '.join(cycle)}",
                "remove the cycle (use a Loop on an activity) or declare NON_BLOCKED")

