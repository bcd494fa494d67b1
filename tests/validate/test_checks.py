"""Each structural check finds its problem (code, severity, message naming the ids, path:line)
and stays silent on the corrected model."""

from __future__ import annotations

import dataclasses

import pytest
from validate_builders import (
    PATH,
    act,
    end,
    field,
    loc,
    one,
    package,
    process,
    start,
    tr,
    with_code,
)

from opspec.errors import Severity
from opspec.model import (
    ActivitySet,
    ActualParameter,
    Application,
    Assignment,
    BasicKind,
    Binary,
    BlockActivity,
    ConditionKind,
    Deadline,
    EventSelector,
    ExternalPackage,
    FormalParameter,
    GatewayType,
    Join,
    Lane,
    Literal,
    Loop,
    MetricDefinition,
    MetricKind,
    Name,
    ParameterMode,
    Participant,
    Pool,
    Reference,
    Route,
    Split,
    SubFlow,
    Task,
    TaskApplication,
    TaskKind,
    WorkflowMode,
)
from opspec.model.checks import check_package, check_process
from opspec.model.sisarl import ActivityDirectives, ProcessDirectives

INT = field("n").type


def test_a_clean_package_has_no_diagnostics() -> None:
    assert check_package(package()) == []


# --------------------------------------------------------------------------- ids

def test_a_duplicate_activity_id_is_an_error_at_the_second_activity() -> None:
    model = package(process(activities=(start(), act("work", 11), act("work", 14), end()),
                            transitions=(tr("t1", "start", "work"), tr("t2", "work", "end"))))
    found = one(check_package(model), "duplicate-id")
    assert found.severity is Severity.ERROR
    assert str(found.location) == f"{PATH}:14"
    assert found.message == "activity id 'work' is used twice in process 'Pump' (first at line 11)"


@pytest.mark.parametrize(("what", "dup"), [
    ("process", "P"), ("transition", "t1"), ("participant", "pump"),
    ("data field", "n")], ids=["process", "transition", "participant", "data-field"])
def test_duplicate_ids_are_found_for_every_kind_of_element(what: str, dup: str) -> None:
    if what == "process":
        model = package(process("P"), process("P", line=40))
    elif what == "transition":
        model = package(process(transitions=(
            tr("t1", "start", "work", 30), tr("t1", "work", "end", 31))))
    elif what == "participant":
        model = package(participants=(Participant(id="pump", location=loc(3)),
                                      Participant(id="pump", location=loc(5))))
    else:
        model = package(process(data_fields=(field("n", 19), field("n", 20))))
    found = one(check_package(model), "duplicate-id")
    assert found.message.startswith(f"{what} id {dup!r} is used twice in ")


def test_a_data_field_with_a_formal_parameters_id_is_one_variable_with_a_warning() -> None:
    # the WfMC publication sample declares 'publish' both ways; the WfMC engines read one
    model = package(process(data_fields=(field("n", 20),),
                            formal_parameters=(FormalParameter(id="n", type=INT,
                                                               location=loc(19)),)))
    diagnostics = check_package(model)
    assert not [d for d in diagnostics if d.code == "duplicate-id"]
    found = one(diagnostics, "parameter-data-field")
    assert found.severity is Severity.WARNING and found.location.line == 20
    assert "formal parameter 'n' (line 19)" in found.message and "one variable" in found.message


def test_an_in_parameter_of_a_process_nothing_calls_is_said_to_start_null() -> None:
    """XPDL gives a process's IN parameters their values from its invoker (a SubFlow's
    actual parameters); a process no SubFlow calls is started by opspec itself, with the
    parameter null. Said at the parameter, for IN and INOUT (not OUT), unless a DataField of
    its Id gives it an initial value or a SubFlow calls the process."""
    formals = (FormalParameter(id="dose", type=INT, location=loc(19)),
               FormalParameter(id="count", type=INT, mode=ParameterMode.INOUT,
                               location=loc(20)),
               FormalParameter(id="result", type=INT, mode=ParameterMode.OUT,
                               location=loc(21)))
    found = [(d.location.line, d.severity) for d in check_package(
        package(process(formal_parameters=formals))) if d.code == "unpassed-parameter"]
    assert found == [(19, Severity.WARNING), (20, Severity.WARNING)]
    with_default = package(process(formal_parameters=formals, data_fields=(field("dose", 30),)))
    assert [d.location.line for d in check_package(with_default)
            if d.code == "unpassed-parameter"] == [20]
    callee = process(formal_parameters=formals)
    caller = process("Caller", activities=(start("s", 40), act("call", 41, body=SubFlow(
        process=callee.id, actual_parameters=(ActualParameter(text="1"),) * 3)), end("e", 42)),
        transitions=(tr("c1", "s", "call", 43), tr("c2", "call", "e", 44)))
    called = package(caller, callee)
    assert not [d for d in check_package(called) if d.code == "unpassed-parameter"]


def test_activity_ids_are_scoped_per_process_and_per_activity_set() -> None:
    aset = ActivitySet(id="S", activities=(start("start", 50), end("end", 51)),
                       transitions=(tr("s1", "start", "end", 52),))
    block = act("block", 13, body=BlockActivity(activity_set="S"))
    model = package(
        process("A", activities=(start(), act("work", 11), block, end()),
                transitions=(tr("t1", "start", "work"), tr("t2", "work", "block"),
                             tr("t3", "block", "end")),
                activity_sets=(aset,)),
        process("B"))
    assert check_package(model) == []


# --------------------------------------------------------------------------- transitions

def test_a_dangling_transition_names_the_activity_and_the_process() -> None:
    model = package(process(transitions=(tr("t1", "start", "work"), tr("T7", "work", "A99", 212),
                                         tr("t2", "work", "end"))))
    found = one(check_package(model), "dangling-transition")
    assert str(found).startswith(
        f"{PATH}:212: error: Transition 'T7' points to activity 'A99', which is not in process "
        "'Pump' (activity ids are scoped per process)")


def test_a_dangling_transition_hint_says_where_the_activity_really_is() -> None:
    other = process("Other", activities=(start(), act("A99", 60), end()),
                    transitions=(tr("o1", "start", "A99"), tr("o2", "A99", "end")))
    model = package(process(transitions=(tr("T7", "A99", "work", 212), tr("t1", "start", "work"),
                                         tr("t2", "work", "end"))), other)
    found = one(check_package(model), "dangling-transition")
    assert "Transition 'T7' comes from activity 'A99'" in found.message
    assert found.hint.startswith("'A99' is an activity of process 'Other': set From to")


def test_a_transition_with_an_empty_end_is_left_to_the_reader() -> None:
    model = package(process(transitions=(tr("t1", "start", "work"), tr("t2", "work", "end"),
                                         tr("t3", "work", ""))))
    assert with_code(check_package(model), "dangling-transition") == []


def test_a_split_naming_a_missing_transition_is_an_error() -> None:
    split = act("work", 11, split=Split(type=GatewayType.AND, transition_refs=("t2", "t9")))
    model = package(process(activities=(start(), split, end())))
    found = one(check_package(model), "undefined-transition-ref")
    assert found.location.line == 11
    assert "TransitionRef 't9'" in found.message and "'work'" in found.message


def test_a_split_naming_another_activitys_transition_is_an_error() -> None:
    split = act("work", 11, split=Split(type=GatewayType.AND, transition_refs=("t1",)))
    model = package(process(activities=(start(), split, end())))
    assert "which leaves activity 'start'" in one(check_package(model),
                                                  "undefined-transition-ref").message


def test_a_split_listing_its_own_transitions_is_fine() -> None:
    split = act("work", 11, split=Split(type=GatewayType.AND, transition_refs=("t2",)))
    assert check_package(package(process(activities=(start(), split, end())))) == []


# --------------------------------------------------------------------------- references

def test_an_undefined_performer_is_an_error() -> None:
    model = package(process(activities=(start(), act("work", 11, performers=("robot",)), end())))
    found = one(check_package(model), "undefined-participant")
    assert found.location.line == 11 and "'robot'" in found.message and "'work'" in found.message


@pytest.mark.parametrize("where", ["process", "external-package", "performer-field"])
def test_performers_defined_elsewhere_in_scope_are_fine(where: str) -> None:
    work = act("work", 11, performers=("robot",))
    if where == "process":
        proc = process(activities=(start(), work, end()),
                       participants=(Participant(id="robot", location=loc(9)),))
        assert check_package(package(proc)) == []
    elif where == "external-package":
        other = package(participants=(Participant(id="robot"),))
        other = dataclasses.replace(other, id="repo", processes=())
        proc = process(activities=(start(), work, end()))
        assert check_package(package(proc), packages={"repo": other}) == []
    else:
        proc = process(activities=(start(), work, end()),
                       data_fields=(field("robot", kind=BasicKind.PERFORMER),))
        assert check_package(package(proc)) == []


def test_an_undefined_lane_performer_is_an_error() -> None:
    pool = Pool(id="pool", process="Pump", location=loc(6),
                lanes=(Lane(id="L1", performers=("ghost",), location=loc(7)),))
    found = one(check_package(package(pools=(pool,))), "undefined-participant")
    assert found.location.line == 7 and "lane 'L1'" in found.message


def _task(app: str, *params: ActualParameter) -> Task:
    return Task(kind=TaskKind.APPLICATION,
                applications=(TaskApplication(application=app, actual_parameters=params),))


def test_an_undefined_application_is_an_error() -> None:
    model = package(process(activities=(start(), act("work", 11, body=_task("beep")), end())))
    found = one(check_package(model), "undefined-application")
    assert found.location.line == 11 and "'beep'" in found.message


def test_an_application_of_the_package_or_of_an_external_package_is_fine() -> None:
    proc = process(activities=(start(), act("work", 11, body=_task("beep")), end()))
    assert check_package(package(proc, applications=(Application(id="beep"),))) == []
    repo = dataclasses.replace(package(applications=(Application(id="beep"),)), id="repo")
    assert check_package(package(proc), packages={"repo": repo}) == []


def test_a_condition_reading_an_undefined_field_is_an_error() -> None:
    cond = Binary(">", Name(("level",)), Literal(3))
    split = act("work", 11, split=Split(type=GatewayType.XOR))
    model = package(process(
        activities=(start(), split, end(), end("other", 13)),
        transitions=(tr("t1", "start", "work"), tr("t2", "work", "end", 31,
                                                    kind=ConditionKind.CONDITION,
                                                    text="level > 3", expression=cond),
                     tr("t3", "work", "other", 32, kind=ConditionKind.OTHERWISE))))
    found = one(check_package(model), "undefined-data-field")
    assert found.location.line == 31
    assert found.message.startswith("the condition of transition 't2' in process 'Pump' reads "
                                    "'level', which is not a data field")
    fixed = dataclasses.replace(model.processes[0], data_fields=(field("level"),))
    assert check_package(dataclasses.replace(model, processes=(fixed,))) == []


@pytest.mark.parametrize("place", ["assignment-target", "assignment-value", "actual-parameter",
                                   "loop", "record-path"])
def test_names_are_checked_wherever_expressions_appear(place: str) -> None:
    work = act("work", 11)
    ghost = Name(("ghost",))
    if place == "assignment-target":
        work = dataclasses.replace(work, assignments=(
            Assignment(target="ghost", text="1", expression=Literal(1), location=loc(15)),))
    elif place == "assignment-value":
        work = dataclasses.replace(work, assignments=(
            Assignment(target="n", text="ghost", expression=ghost, location=loc(15)),))
    elif place == "actual-parameter":
        work = dataclasses.replace(work, body=_task("beep", ActualParameter(
            text="ghost", expression=ghost, location=loc(15))))
    elif place == "loop":
        work = dataclasses.replace(work, loop=Loop(condition=ghost, condition_text="ghost"))
    else:
        work = dataclasses.replace(work, assignments=(Assignment(
            target="n", text="ghost.total", expression=Name(("ghost", "total")),
            location=loc(15)),))
    model = package(process(activities=(start(), work, end()), data_fields=(field("n"),)),
                    applications=(Application(id="beep"),))
    found = one(check_package(model), "undefined-data-field")
    assert "'ghost'" in found.message
    assert found.location.line == (11 if place == "loop" else 15)


def test_formal_parameters_and_package_fields_are_in_scope() -> None:
    cond = Binary("and", Name(("hour",)), Name(("dose",)))
    work = act("work", 11, loop=Loop(condition=cond, condition_text="hour && dose"))
    model = package(process(activities=(start(), work, end()),
                            formal_parameters=(FormalParameter(id="hour", type=INT),)),
                    data_fields=(field("dose"),))
    # in scope: no undefined-name; only that nothing passes 'hour' to a process run on its own
    assert [d.code for d in check_package(model)] == ["unpassed-parameter"]


def test_a_subflow_to_a_missing_process_is_an_error_and_one_into_another_package_too() -> None:
    call = act("call", 11, body=SubFlow(process="Refill"))
    model = package(process(activities=(start(), call, end()),
                            transitions=(tr("t1", "start", "call"), tr("t2", "call", "end"))))
    found = one(check_package(model), "undefined-subflow")
    assert found.location.line == 11 and "'Refill'" in found.message
    # found in a loaded package, but the engine runs subflows within one package only
    lib = dataclasses.replace(package(process("Refill")), id="lib")
    found = one(check_package(model, packages={"lib": lib, "pkg": model}), "external-subflow")
    assert found.location.line == 11 and "of external package 'lib'" in found.message
    assert not [d for d in check_package(model, packages={"lib": lib, "pkg": model})
                if d.code == "undefined-subflow"]


def test_parameter_counts_must_match_the_called_process() -> None:
    called = process("Refill", formal_parameters=(FormalParameter(id="a", type=INT),
                                                  FormalParameter(id="b", type=INT)))
    call = act("call", 11, body=SubFlow(process="Refill", actual_parameters=(
        ActualParameter(text="1", expression=Literal(1)),)))
    model = package(process(activities=(start(), call, end()),
                            transitions=(tr("t1", "start", "call"), tr("t2", "call", "end"))),
                    called)
    found = one(check_package(model), "parameter-count-mismatch")
    assert "passes 1 actual parameter to process 'Refill', which declares 2" in found.message


def test_a_block_activity_naming_a_missing_activity_set_is_an_error() -> None:
    block = act("block", 11, body=BlockActivity(activity_set="S9"))
    model = package(process(activities=(start(), block, end()),
                            transitions=(tr("t1", "start", "block"), tr("t2", "block", "end"))))
    found = one(check_package(model), "undefined-activity-set")
    assert found.location.line == 11 and "'S9'" in found.message


def test_an_activity_set_no_block_uses_is_a_warning() -> None:
    aset = ActivitySet(id="S", activities=(start("s", 50),), location=loc(49))
    found = one(check_package(package(process(activity_sets=(aset,)))), "unused-activity-set")
    assert found.severity is Severity.WARNING and found.location.line == 49


def test_references_and_attached_events_must_name_activities_of_the_level() -> None:
    ref = act("again", 13, body=Reference(activity="nowhere"))
    model = package(process(activities=(start(), act("work", 11), ref, end()),
                            transitions=(tr("t1", "start", "work"), tr("t2", "work", "again"),
                                         tr("t3", "again", "end"))))
    assert one(check_package(model), "undefined-activity-reference").location.line == 13


# --------------------------------------------------------------------------- flow

def test_a_process_whose_activities_all_have_incoming_transitions_has_no_start() -> None:
    model = package(process(activities=(act("a", 10), act("b", 11)),
                            transitions=(tr("t1", "a", "b"), tr("t2", "b", "a"))))
    found = one(check_package(model), "no-start-activity")
    assert found.severity is Severity.ERROR and found.location.line == 8
    assert found.message.startswith("process 'Pump' has no start activity")
    assert with_code(check_package(model), "unreachable-activity") == []


def test_an_activity_nothing_leads_to_is_unreachable() -> None:
    model = package(process(activities=(start(), act("work", 11), act("orphan", 14), end()),
                            transitions=(tr("t1", "start", "work"), tr("t2", "work", "end"),
                                         tr("t3", "orphan", "orphan"))))
    found = one(check_package(model), "unreachable-activity")
    assert found.severity is Severity.WARNING and found.location.line == 14
    assert "'orphan'" in found.message and "'start'" in found.message


def _deadline(name: str | None) -> Deadline:
    return Deadline(duration_text="PT5S", duration=Literal(5), exception_name=name,
                    location=loc(16))


def test_a_deadline_without_an_exception_transition_is_an_error() -> None:
    work = act("work", 11, deadlines=(_deadline("late"),))
    model = package(process(activities=(start(), work, end())))
    found = one(check_package(model), "deadline-without-exception-path")
    assert found.location.line == 16 and "'late'" in found.message and "'work'" in found.message


@pytest.mark.parametrize(("kind", "name", "caught"), [
    (ConditionKind.EXCEPTION, "late", True),
    (ConditionKind.EXCEPTION, None, True),
    (ConditionKind.DEFAULTEXCEPTION, None, True),
    (ConditionKind.EXCEPTION, "other", False),
], ids=["named", "any-exception", "default", "wrong-name"])
def test_an_exception_transition_catches_the_deadline(kind: ConditionKind, name: str | None,
                                                      caught: bool) -> None:
    work = act("work", 11, deadlines=(_deadline("late"),))
    model = package(process(
        activities=(start(), work, end(), end("late_end", 13)),
        transitions=(tr("t1", "start", "work"), tr("t2", "work", "end"),
                     tr("t3", "work", "late_end", kind=kind, exception=name))))
    found = with_code(check_package(model), "deadline-without-exception-path")
    assert (found == []) is caught


def _xor_and(and_split: bool, *, via_condition: bool = False) -> list[str]:
    """start -> X (split) -> a | b -> J (AND join) -> end."""
    split_type = GatewayType.AND if and_split else GatewayType.XOR
    x = act("X", 11, body=Route(gateway=split_type), split=Split(type=split_type))
    j = act("J", 14, body=Route(gateway=GatewayType.AND), join=Join(type=GatewayType.AND))
    activities = [start(), x, act("a", 12), act("b", 13), j, end()]
    if and_split:
        branches = [tr("ta", "X", "a"), tr("tb", "X", "b")]
    else:
        branches = [tr("ta", "X", "a", kind=ConditionKind.CONDITION, text="n > 0",
                       expression=Binary(">", Name(("n",)), Literal(0))),
                    tr("tb", "X", "b", kind=ConditionKind.OTHERWISE)]
    transitions = [tr("t0", "start", "X"), *branches,
                   tr("ja", "a", "J"), tr("jb", "b", "J"), tr("te", "J", "end")]
    if via_condition:
        # each branch reaches J only through a further XOR split on data
        transitions = transitions[:3] + [transitions[-1]]
        for branch, line in (("a", 15), ("b", 17)):
            guard = act(f"{branch}C", line, split=Split(type=GatewayType.XOR))
            activities += [guard, end(f"{branch}_elsewhere", line + 1)]
            transitions += [tr(f"{branch}g", branch, f"{branch}C"),
                            tr(f"{branch}j", f"{branch}C", "J", kind=ConditionKind.CONDITION,
                               text="n > 1", expression=Binary(">", Name(("n",)), Literal(1))),
                            tr(f"{branch}e", f"{branch}C", f"{branch}_elsewhere",
                               kind=ConditionKind.OTHERWISE)]
    model = package(process(activities=tuple(activities), transitions=tuple(transitions),
                            data_fields=(field("n"),)))
    return [str(d) for d in check_package(model)]


def test_an_and_join_fed_by_the_branches_of_an_xor_split_deadlocks() -> None:
    found = _xor_and(False)
    assert len(found) == 1
    assert found[0].startswith(f"{PATH}:14: error: AND-join 'J' in process 'Pump' is fed only "
                               "by exclusive split 'X': taking its transition 'ta' brings a "
                               "token on 'ja' but never on 'jb'")


def test_an_and_join_after_an_and_split_does_not_deadlock() -> None:
    assert _xor_and(True) == []


def test_a_deadlock_that_depends_on_further_conditions_is_only_a_warning() -> None:
    found = [line for line in _xor_and(False, via_condition=True) if "AND-join" in line]
    assert len(found) == 1 and ": warning: " in found[0]
    assert "can reach 'aj' (through further conditions) but never 'bj'" in found[0]


def test_conditions_out_of_an_activity_without_a_split_are_a_warning() -> None:
    cond = Binary(">", Name(("n",)), Literal(1))
    transitions = (tr("t1", "start", "work"),
                   tr("t2", "work", "end", 31, kind=ConditionKind.CONDITION, text="n > 1",
                      expression=cond))
    model = package(process(transitions=transitions, data_fields=(field("n"),)))
    found = one(check_package(model), "condition-without-split")
    assert found.severity is Severity.WARNING and found.location.line == 31
    split = act("work", 11, performers=("pump",), split=Split(type=GatewayType.XOR))
    fixed = package(process(activities=(start(), split, end()), transitions=transitions,
                            data_fields=(field("n"),)))
    assert with_code(check_package(fixed), "condition-without-split") == []


def test_two_otherwise_transitions_from_one_activity_are_an_error() -> None:
    split = act("work", 11, split=Split(type=GatewayType.XOR))
    model = package(process(
        activities=(start(), split, end(), end("e2", 13)),
        transitions=(tr("t1", "start", "work"),
                     tr("t2", "work", "end", 31, kind=ConditionKind.OTHERWISE),
                     tr("t3", "work", "e2", 32, kind=ConditionKind.OTHERWISE))))
    found = one(check_package(model), "duplicate-otherwise")
    assert found.location.line == 32 and "'t2' and 't3'" in found.message


def test_an_xor_split_with_several_unconditional_branches_is_a_warning() -> None:
    split = act("work", 11, split=Split(type=GatewayType.XOR, transition_refs=("t2", "t3")))
    model = package(process(activities=(start(), split, end(), end("e2", 13)),
                            transitions=(tr("t1", "start", "work"), tr("t2", "work", "end"),
                                         tr("t3", "work", "e2"))))
    found = one(check_package(model), "unconditional-xor-branches")
    assert found.severity is Severity.WARNING and "'t2' and 't3'" in found.message


def test_a_cycle_in_a_loop_blocked_package_breaks_its_conformance_class() -> None:
    proc = process(activities=(start(), act("a", 11), act("b", 12), end()),
                   transitions=(tr("t1", "start", "a"), tr("t2", "a", "b"), tr("t3", "b", "a"),
                                tr("t4", "b", "end")))
    found = one(check_package(package(proc, conformance_class="LOOP_BLOCKED")),
                "conformance-cycle")
    assert "a -> b -> a" in found.message
    assert with_code(check_package(package(proc, conformance_class="NON_BLOCKED")),
                     "conformance-cycle") == []


# --------------------------------------------------------------------------- SISARL

def test_a_period_of_zero_is_an_error() -> None:
    proc = process(directives=ProcessDirectives(period=0.0))
    found = one(check_package(package(proc)), "bad-period")
    assert found.severity is Severity.ERROR and found.location.line == 8


def test_a_negative_priority_increment_is_a_warning() -> None:
    work = act("work", 11, performers=("pump",),
               directives=ActivityDirectives(priority_increment=-1))
    found = one(check_package(package(process(activities=(start(), work, end())))),
                "negative-priority-increment")
    assert found.severity is Severity.WARNING and found.location.line == 11


@pytest.mark.parametrize(("selector", "names"), [
    (EventSelector(event="process.started", process="Pmp"), "'Pmp'"),
    (EventSelector(event="activity.completed", process="Pump", activity="wrk"), "'wrk'"),
    (EventSelector(event="activity.completed", activity="wrk"), "'wrk'"),
], ids=["process", "activity-of-process", "activity-anywhere"])
def test_a_metric_selecting_a_missing_process_or_activity_is_an_error(
        selector: EventSelector, names: str) -> None:
    metric = MetricDefinition(name="m", kind=MetricKind.COUNT, select=selector, location=loc(90))
    found = one(check_package(package(metrics=(metric,))), "undefined-metric-target")
    assert found.location.line == 90 and names in found.message


def test_metrics_selecting_existing_targets_are_fine() -> None:
    count = MetricDefinition(name="m", kind=MetricKind.COUNT, select=EventSelector(
        event="activity.completed", process="Pump", activity="work"))
    ratio = MetricDefinition(name="r", kind=MetricKind.RATIO, numerator="m", denominator="m")
    assert check_package(package(metrics=(count, ratio))) == []
    bad = MetricDefinition(name="r", kind=MetricKind.RATIO, numerator="m", denominator="x")
    assert "'x'" in one(check_package(package(metrics=(count, bad))), "undefined-metric").message


def test_modes_must_name_existing_workflows_and_processes_existing_modes() -> None:
    modes = (WorkflowMode(id="run", workflows=("Pump", "Ghost"), initial=True),)
    found = one(check_package(package(modes=modes)), "undefined-mode-workflow")
    assert "'Ghost'" in found.message and found.location.line == 2
    proc = process(directives=ProcessDirectives(mode="dock"))
    found = one(check_package(package(proc, modes=modes)), "undefined-mode")
    assert "'dock'" in found.message


# --------------------------------------------------------------------------- API

def test_check_process_checks_one_process_only() -> None:
    broken = process("B", transitions=(tr("x", "start", "nowhere"),))
    model = package(process("A"), broken, process("A", line=70))
    assert {d.code for d in check_package(model)} >= {"duplicate-id", "dangling-transition"}
    assert {d.code for d in check_process(model.processes[0], model)} == set()
    assert "dangling-transition" in {d.code for d in check_process(broken, model)}


def test_elements_without_locations_are_reported_at_the_package_file() -> None:
    model = package(process(activities=(start(), act("work", 11), end()),
                            transitions=(tr("t1", "start", "work"),
                                         dataclasses.replace(tr("T7", "work", "A99"),
                                                             location=None))))
    found = one(check_package(model), "dangling-transition")
    assert found.location.path == PATH and found.location.line is None


def test_an_external_package_declaration_alone_defines_nothing() -> None:
    work = act("work", 11, performers=("robot",))
    model = package(process(activities=(start(), work, end())),
                    external_packages=(ExternalPackage(id="repo", href="repo.xpdl"),))
    assert one(check_package(model), "undefined-participant")
