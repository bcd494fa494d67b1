"""The SISARL-XPDL preprocessor: augmented elements -> standard XPDL 2.1.

Each behaviour-coordination built-in (an activity with a :class:`CoordinationBuiltIn`) becomes
a *compound built-in activity*: the activity keeps its id, name, performers, restrictions,
deadlines and directives, but its body becomes a ``BlockActivity`` that references a generated
``ActivitySet`` made only of Routes and plain activities (and, for push/pull/mode change, of a
Task calling an opspec application). Engine directives (period, priority increment, AutoRun,
triggers…) are written as ``ExtendedAttribute Name="opspec:…"`` by the writer. The result is
standard XPDL 2.1 that validates against ``bpmnxpdl_31.xsd``.

The exact translation of each built-in is documented in ``docs/sisarl-xpdl.md`` (section
*Preprocessing*); keep the two in step.

Generated ids are ``<activity>.<role>`` (``arbitrate.pick1``), made unique in the whole package
because the schema requires unique Activity and ActivitySet ids package-wide. Generated data
fields (the voter's tallies) are identifiers ``_vote_<activity>_<n>`` so conditions can name
them.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable
from dataclasses import dataclass

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model import (
    Activity,
    ActivitySet,
    ActualParameter,
    Application,
    Assignment,
    BasicKind,
    BasicType,
    Binary,
    BlockActivity,
    Condition,
    ConditionKind,
    CoordinationBuiltIn,
    CoordinationKind,
    DataField,
    Expression,
    ExtendedAttribute,
    FormalParameter,
    GatewayType,
    Join,
    Literal,
    Name,
    NoImplementation,
    Package,
    ParameterMode,
    Route,
    Split,
    Task,
    TaskApplication,
    TaskKind,
    Transition,
    WorkflowProcess,
)
from opspec.xpdl.writer import expression_text, write_xpdl

__all__ = [
    "MODE_CHANGE_APPLICATION",
    "PULL_APPLICATION",
    "PUSH_APPLICATION",
    "PreprocessResult",
    "preprocess",
    "preprocess_to_xpdl",
]

PUSH_APPLICATION = "opspec.supervisor.push"
PULL_APPLICATION = "opspec.supervisor.pull"
MODE_CHANGE_APPLICATION = "opspec.engine.mode_change"

_STRING = BasicType(kind=BasicKind.STRING)
_INTEGER = BasicType(kind=BasicKind.INTEGER)


def _application(app_id: str, name: str, description: str,
                 *parameters: tuple[str, ParameterMode]) -> Application:
    """A built-in application whose formal parameters (name, mode) are all text."""
    return Application(id=app_id, name=name, description=description, formal_parameters=tuple(
        FormalParameter(id=p, type=_STRING, mode=mode) for p, mode in parameters))


_IN, _OUT = ParameterMode.IN, ParameterMode.OUT
# The applications the generated tasks call; added to the package when it lacks them.
_APPLICATIONS = (
    _application(PUSH_APPLICATION, "Push data to a supervisor channel",
                 "opspec built-in: hold VALUE in CHANNEL until a receiver pulls it",
                 ("channel", _IN), ("value", _IN)),
    _application(PULL_APPLICATION, "Pull data from a supervisor channel",
                 "opspec built-in: take the value held in CHANNEL into VALUE",
                 ("channel", _IN), ("value", _OUT)),
    _application(MODE_CHANGE_APPLICATION, "Change the device mode",
                 "opspec built-in: switch the running workflows to those of MODE", ("mode", _IN)),
)


@dataclass(frozen=True, slots=True)
class PreprocessResult:
    """The standard-XPDL model and the problems found while translating."""

    package: Package
    diagnostics: tuple[Diagnostic, ...] = ()


# --------------------------------------------------------------------------- small builders


def _name(ref: str) -> Name:
    return Name(tuple(ref.split(".")))


def _condition(expression: Expression) -> Condition:
    return Condition(kind=ConditionKind.CONDITION, text=expression_text(expression),
                     expression=expression)


_OTHERWISE = Condition(kind=ConditionKind.OTHERWISE)
_ALWAYS = Condition()


def _assign(target: str, expression: Expression) -> Assignment:
    return Assignment(target=target, text=expression_text(expression), expression=expression)


def _holds_command(ref: str) -> Expression:
    """``ref != null && ref != ""``: the input carries a command this cycle."""
    return Binary("and", Binary("!=", _name(ref), Literal(None)),
                  Binary("!=", _name(ref), Literal("")))


class _Ids:
    """Fresh ids, unique in the whole package (the schema keys Activity ids package-wide)."""

    def __init__(self, used: Iterable[str]) -> None:
        self.used = set(used)

    def fresh(self, base: str) -> str:
        base = re.sub(r"[^\w.:-]", "_", base)
        candidate, n = base, 1
        while candidate in self.used:
            n += 1
            candidate = f"{base}.{n}"
        self.used.add(candidate)
        return candidate


def _all_ids(package: Package) -> set[str]:
    ids = {package.id}
    for pool in package.pools:
        ids.add(pool.id)
        ids.update(lane.id for lane in pool.all_lanes())
    for process in package.processes:
        ids.add(process.id)
        ids.update(field.id for field in process.data_fields)
        ids.update(t.id for t in process.transitions)
        for activity_set in process.activity_sets:
            ids.add(activity_set.id)
            ids.update(t.id for t in activity_set.transitions)
        ids.update(activity.id for activity in process.all_activities())
    ids.update(field.id for field in package.data_fields)
    ids.update(application.id for application in package.applications)
    return ids


@dataclass
class _Set:
    """An activity set under construction."""

    ids: _Ids
    owner: Activity
    activities: list[Activity] = dataclasses.field(default_factory=list)
    transitions: list[Transition] = dataclasses.field(default_factory=list)

    def add(self, role: str, name: str, **fields: object) -> Activity:
        activity = Activity(id=self.ids.fresh(f"{self.owner.id}.{role}"), name=name,
                            lane=self.owner.lane, **fields)  # type: ignore[arg-type]
        self.activities.append(activity)
        return activity

    def link(self, source: Activity, target: Activity,
             condition: Condition = _ALWAYS) -> Transition:
        transition = Transition(id=self.ids.fresh(f"{self.owner.id}.t{len(self.transitions) + 1}"),
                                source=source.id, target=target.id, condition=condition)
        self.transitions.append(transition)
        return transition

    def route(self, role: str, name: str, *, join: bool = False) -> Activity:
        return self.add(role, name, body=Route(gateway=GatewayType.XOR),
                        join=Join(type=GatewayType.XOR) if join else None)

    def set_split(self, activity: Activity, transitions: list[Transition]) -> None:
        """Give ``activity`` its XOR split with ``transitions`` in evaluation order."""
        index = self.activities.index(activity)
        self.activities[index] = dataclasses.replace(
            activity, split=Split(type=GatewayType.XOR,
                                  transition_refs=tuple(t.id for t in transitions)))


# --------------------------------------------------------------------------- the built-ins


def _arbiter(builtin: CoordinationBuiltIn, s: _Set, output: str) -> None:
    decide = s.route("decide", "Arbiter: highest-priority input with a command")
    done = s.route("done", "Arbiter: done", join=True)
    branches = []
    for rank, ref in enumerate(builtin.inputs, start=1):
        pick = s.add(f"pick{rank}", f"Arbiter: take {ref}",
                     assignments=(_assign(output, _name(ref)),))
        branches.append(s.link(decide, pick, _condition(_holds_command(ref))))
        s.link(pick, done)
    idle = s.add("idle", "Arbiter: no input has a command",
                 assignments=(_assign(output, Literal(None)),))
    branches.append(s.link(decide, idle, _OTHERWISE))
    s.link(idle, done)
    s.set_split(decide, branches)


def _tally_name(owner: str, index: int) -> str:
    return f"_vote_{re.sub(r'[^0-9A-Za-z_]', '_', owner)}_{index}"


def _voter(builtin: CoordinationBuiltIn, s: _Set, output: str,
           new_fields: list[DataField]) -> None:
    options = builtin.options
    tallies = []
    for index, option in enumerate(options, start=1):
        tally = _tally_name(s.owner.id, index)
        tallies.append(tally)
        new_fields.append(DataField(id=tally, name=f"votes for {option!r} ({s.owner.id})",
                                    type=_INTEGER, initial_value="0", initial=0))
    reset = s.add("reset", "Voter: clear the tallies",
                  assignments=tuple(_assign(t, Literal(0)) for t in tallies))
    previous = reset
    for number, ref in enumerate(builtin.inputs, start=1):
        read = s.route(f"read{number}", f"Voter: read the vote of {ref}")
        s.link(previous, read)
        counted = s.route(f"counted{number}", f"Voter: vote of {ref} counted", join=True)
        branches = []
        for index, option in enumerate(options):
            count = s.add(f"count{number}_{index + 1}", f"Voter: {ref} votes {option}",
                          assignments=(_assign(tallies[index],
                                               Binary("+", Name((tallies[index],)),
                                                      Literal(1))),))
            branches.append(s.link(read, count, _condition(
                Binary("==", _name(ref), Literal(option)))))
            s.link(count, counted)
        branches.append(s.link(read, counted, _OTHERWISE))   # no vote, or not an option
        s.set_split(read, branches)
        previous = counted
    decide = s.route("decide", "Voter: the option with the most votes")
    s.link(previous, decide)
    done = s.route("done", "Voter: done", join=True)
    branches = []
    # Nobody voted for a listed option: the output is null (as the engine's voter gives).
    nobody: Expression = Binary("==", Name((tallies[0],)), Literal(0))
    for tally in tallies[1:]:
        nobody = Binary("and", nobody, Binary("==", Name((tally,)), Literal(0)))
    abstain = s.add("none", "Voter: no vote for any option",
                    assignments=(_assign(output, Literal(None)),))
    branches.append(s.link(decide, abstain, _condition(nobody)))
    s.link(abstain, done)
    for index, option in enumerate(options):
        pick = s.add(f"pick{index + 1}", f"Voter: {option} wins",
                     assignments=(_assign(output, Literal(option)),))
        if index == len(options) - 1:
            condition = _OTHERWISE
        else:
            # Ties go to the earlier option: beat every earlier one, match every later one.
            mine = Name((tallies[index],))
            tests: list[Expression] = [
                Binary(">" if other < index else ">=", mine, Name((tallies[other],)))
                for other in range(len(options)) if other != index
            ]
            expression = tests[0]
            for test in tests[1:]:
                expression = Binary("and", expression, test)
            condition = _condition(expression)
        branches.append(s.link(decide, pick, condition))
        s.link(pick, done)
    s.set_split(decide, branches)


def _superposition(builtin: CoordinationBuiltIn, s: _Set, output: str) -> None:
    total: Expression | None = None
    for index, ref in enumerate(builtin.inputs):
        weight = builtin.weights[index] if index < len(builtin.weights) else 1.0
        term: Expression = Binary("*", Literal(weight), _name(ref))
        total = term if total is None else Binary("+", total, term)
    s.add("combine", "Superposition: weighted sum of the inputs",
          assignments=(_assign(output, total if total is not None else Literal(0.0)),))


def _application_task(s: _Set, role: str, name: str, application: str,
                      parameters: tuple[str | Expression, ...]) -> None:
    actual = tuple(
        ActualParameter(text=p, expression=_name(p)) if isinstance(p, str)
        else ActualParameter(text=expression_text(p), expression=p)
        for p in parameters
    )
    s.add(role, name, body=Task(kind=TaskKind.APPLICATION, applications=(
        TaskApplication(application=application, actual_parameters=actual),)))


def _translate(builtin: CoordinationBuiltIn, s: _Set, new_fields: list[DataField],
               report: _Reporter) -> bool:
    kind = builtin.kind
    output = builtin.output or ""
    if kind in (CoordinationKind.ARBITER, CoordinationKind.VOTER,
                CoordinationKind.SUPERPOSITION, CoordinationKind.PULL_DATA) and not output:
        report.error(s.owner, f"the {kind.value} built-in has no output data field",
                     "name the data field that receives the result (Output=… / Ref=…)")
        return False
    if kind is CoordinationKind.ARBITER:
        _arbiter(builtin, s, output)
    elif kind is CoordinationKind.VOTER:
        if not builtin.options:
            report.error(s.owner, "the voter built-in has no Options",
                         "list the commands voted on: Options=\"forward left right\"")
            return False
        _voter(builtin, s, output, new_fields)
    elif kind is CoordinationKind.SUPERPOSITION:
        _superposition(builtin, s, output)
    elif kind is CoordinationKind.PUSH_DATA:
        if not builtin.inputs or builtin.channel is None:
            report.error(s.owner, "the push-data built-in needs a Channel and a Ref",
                         "write <opspec:PushData Channel=\"…\" Ref=\"data_field\"/>")
            return False
        _application_task(s, "call", f"Push {builtin.inputs[0]} to {builtin.channel}",
                          PUSH_APPLICATION, (Literal(builtin.channel), builtin.inputs[0]))
    elif kind is CoordinationKind.PULL_DATA:
        if builtin.channel is None:
            report.error(s.owner, "the pull-data built-in needs a Channel",
                         "write <opspec:PullData Channel=\"…\" Ref=\"data_field\"/>")
            return False
        _application_task(s, "call", f"Pull {output} from {builtin.channel}",
                          PULL_APPLICATION, (Literal(builtin.channel), output))
    elif kind is CoordinationKind.MODE_CHANGE:
        if not builtin.target_mode:
            report.error(s.owner, "the mode-change built-in names no mode",
                         "write <opspec:ModeChange To=\"mode_id\"/>")
            return False
        _application_task(s, "call", f"Change to mode {builtin.target_mode}",
                          MODE_CHANGE_APPLICATION, (Literal(builtin.target_mode),))
    return True


# --------------------------------------------------------------------------- driver


class _Reporter:
    def __init__(self, package: Package) -> None:
        self.diagnostics: list[Diagnostic] = []
        self.path = package.source or "<package>"

    def _where(self, activity: Activity) -> SourceLocation:
        return activity.location or SourceLocation(self.path)

    def error(self, activity: Activity, message: str, hint: str) -> None:
        self.diagnostics.append(Diagnostic(self._where(activity), Severity.ERROR,
                                           "bad-builtin", f"activity '{activity.id}': {message}",
                                           hint))

    def warning(self, activity: Activity, code: str, message: str, hint: str) -> None:
        self.diagnostics.append(Diagnostic(self._where(activity), Severity.WARNING, code,
                                           f"activity '{activity.id}': {message}", hint))


_SET_NAMES = {
    CoordinationKind.ARBITER: "fixed-priority arbiter",
    CoordinationKind.VOTER: "voter",
    CoordinationKind.SUPERPOSITION: "superposition",
    CoordinationKind.PUSH_DATA: "push data",
    CoordinationKind.PULL_DATA: "pull data",
    CoordinationKind.MODE_CHANGE: "mode change",
}


def _without_builtin_attribute(attributes: tuple[ExtendedAttribute, ...]
                               ) -> tuple[ExtendedAttribute, ...]:
    return tuple(a for a in attributes if a.name != "opspec:BuiltIn")


def _expand(activity: Activity, ids: _Ids, new_sets: list[ActivitySet],
            new_fields: list[DataField], report: _Reporter) -> tuple[Activity, bool]:
    builtin = activity.coordination
    assert builtin is not None
    if not isinstance(activity.body, (Route, NoImplementation)):
        report.warning(activity, "builtin-replaces-body",
                       f"the {builtin.kind.value} built-in replaces the activity's "
                       f"{type(activity.body).__name__}",
                       "put the built-in on an activity of its own")
    s = _Set(ids, activity)
    if not _translate(builtin, s, new_fields, report):
        return activity, False
    set_id = ids.fresh(f"{activity.id}.{builtin.kind.value}")
    new_sets.append(ActivitySet(id=set_id,
                                name=f"{_SET_NAMES[builtin.kind]} built-in of {activity.id} "
                                     "(generated by opspec preprocess)",
                                activities=tuple(s.activities),
                                transitions=tuple(s.transitions)))
    expanded = dataclasses.replace(
        activity,
        body=BlockActivity(activity_set=set_id, start_activity=s.activities[0].id),
        coordination=None,
        extended_attributes=_without_builtin_attribute(activity.extended_attributes),
    )
    return expanded, True


def _preprocess_process(process: WorkflowProcess, ids: _Ids,
                        report: _Reporter) -> tuple[WorkflowProcess, set[str]]:
    new_sets: list[ActivitySet] = []
    new_fields: list[DataField] = []
    used_apps: set[str] = set()

    def expand_all(activities: tuple[Activity, ...]) -> tuple[Activity, ...]:
        out = []
        for activity in activities:
            if activity.coordination is not None:
                kind = activity.coordination.kind
                activity, ok = _expand(activity, ids, new_sets, new_fields, report)
                if ok:
                    used_apps.update({CoordinationKind.PUSH_DATA: {PUSH_APPLICATION},
                                      CoordinationKind.PULL_DATA: {PULL_APPLICATION},
                                      CoordinationKind.MODE_CHANGE: {MODE_CHANGE_APPLICATION},
                                      }.get(kind, set()))
            out.append(activity)
        return tuple(out)

    activities = expand_all(process.activities)
    sets = tuple(dataclasses.replace(s, activities=expand_all(s.activities))
                 for s in process.activity_sets)
    result = dataclasses.replace(
        process,
        activities=activities,
        activity_sets=sets + tuple(new_sets),
        data_fields=process.data_fields + tuple(new_fields),
    )
    return result, used_apps


def preprocess(package: Package) -> PreprocessResult:
    """Translate every coordination built-in of ``package`` into a compound built-in activity.

    The returned package has no :class:`CoordinationBuiltIn` left (except on activities whose
    built-in was unusable; each such is an ``error`` diagnostic and is left untouched), gains the
    opspec applications the generated tasks call, and keeps everything else as it was.
    """
    ids = _Ids(_all_ids(package))
    report = _Reporter(package)
    processes = []
    used_apps: set[str] = set()
    for process in package.processes:
        new_process, apps = _preprocess_process(process, ids, report)
        processes.append(new_process)
        used_apps |= apps
    declared = {application.id for application in package.applications}
    added = tuple(a for a in _APPLICATIONS if a.id in used_apps and a.id not in declared)
    result = dataclasses.replace(package, processes=tuple(processes),
                                 applications=package.applications + added)
    return PreprocessResult(result, tuple(report.diagnostics))


def preprocess_to_xpdl(package: Package) -> tuple[bytes, tuple[Diagnostic, ...]]:
    """:func:`preprocess`, then the standard XPDL 2.1 text of the result."""
    result = preprocess(package)
    return write_xpdl(result.package), result.diagnostics
