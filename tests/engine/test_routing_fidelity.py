"""Routing as XPDL 2.1 / BPMN 2.0 define it, from XPDL text through the real reader.

Each test states the behaviour the definition implies (workflow patterns of van der Aalst et
al. 2003; BPMN 2.0 §13 execution semantics; XPDL 2.1 §7.6) and checks the trace for it:
complex joins (discriminator, N-out-of-M), conditional flows without a split, multi-instance
loops with each MI_FlowCondition, implicit termination.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pytest

from opspec.engine.simulation import RunResult, Simulation
from opspec.errors import SpecError
from opspec.model.checks import check_package
from opspec.xpdl.loader import load_spec

NS = "http://www.wfmc.org/2008/XPDL2.1"


def takes(seconds: float) -> str:
    return ('<ExtendedAttributes><ExtendedAttribute Name="opspec:Duration" '
            f'Value="ConstantParameter({seconds})"/></ExtendedAttributes>')


def activity(aid: str, *, seconds: float | None = None, join: str | None = None,
             split: str | None = None, route: str | None = None, extra: str = "") -> str:
    body = (f"<Route {route}/>" if route is not None
            else "<Implementation><No/></Implementation>")
    restriction = ""
    if join or split:
        restriction = ("<TransitionRestrictions><TransitionRestriction>"
                       + (f'<Join Type="{join}"/>' if join else "")
                       + (f'<Split Type="{split}"/>' if split else "")
                       + "</TransitionRestriction></TransitionRestrictions>")
    duration = takes(seconds) if seconds is not None else ""
    return f'<Activity Id="{aid}">{body}{extra}{restriction}{duration}</Activity>'


def transition(source: str, target: str, condition: str | None = None) -> str:
    cond = ""
    if condition == "otherwise":
        cond = '<Condition Type="OTHERWISE"/>'
    elif condition is not None:
        cond = f'<Condition Type="CONDITION"><Expression>{condition}</Expression></Condition>'
    return (f'<Transition Id="{source}_{target}" From="{source}" To="{target}">{cond}'
            "</Transition>")


def spec(tmp_path: Path, activities: Sequence[str], transitions: Sequence[str],
         fields: str = "") -> Path:
    text = (f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{NS}" Id="routing">'
            '<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor>'
            '<Created>2026</Created></PackageHeader>'
            f'<WorkflowProcesses><WorkflowProcess Id="p"><ProcessHeader/>{fields}'
            f"<Activities>{''.join(activities)}</Activities>"
            f"<Transitions>{''.join(transitions)}</Transitions>"
            "</WorkflowProcess></WorkflowProcesses></Package>")
    path = tmp_path / "routing.xpdl"
    path.write_text(text)
    return path


def run(path: Path, until: float | None = 1000.0) -> RunResult:
    sim = Simulation(load_spec(path), keep_trace=True)
    return sim.run(until=until)


def starts(result: RunResult, aid: str) -> list[float]:
    assert result.trace is not None
    return [e.time for e in result.trace
            if e.kind == "activity.started" and e.activity == aid]


def completed_at(result: RunResult) -> list[float]:
    assert result.trace is not None
    return [e.time for e in result.trace if e.kind == "process.completed"]


def integer_field(fid: str, value: int) -> str:
    return (f'<DataFields><DataField Id="{fid}"><DataType><BasicType Type="INTEGER"/>'
            f"</DataType><InitialValue>{value}</InitialValue></DataField></DataFields>")


# --------------------------------------------------------------------- complex joins
def three_branches(condition: str) -> tuple[list[str], list[str]]:
    acts = [activity("A", split="Parallel"), activity("B", seconds=1),
            activity("C", seconds=2), activity("D", seconds=3),
            activity("J", join="Complex", route=f'GatewayType="Complex" '
                     f'IncomingCondition="{condition}"'),
            activity("E")]
    trans = [transition("A", "B"), transition("A", "C"), transition("A", "D"),
             transition("B", "J"), transition("C", "J"), transition("D", "J"),
             transition("J", "E")]
    return acts, trans


def test_discriminator_fires_once_on_the_first_branch_and_ignores_the_others(
        tmp_path: Path) -> None:
    """WCP9: the first completed branch activates the next activity; the rest are ignored;
    the case completes when every branch has been."""
    result = run(spec(tmp_path, *three_branches("activationCount &gt;= 1")))
    assert starts(result, "J") == [1.0]
    assert starts(result, "E") == [1.0]
    assert completed_at(result) == [3.0]
    assert result.summary["deadlocks"] == []


def test_n_out_of_m_join_fires_when_n_branches_have_completed(tmp_path: Path) -> None:
    """WCP30 (structured partial join, 2-out-of-3): E starts when the second branch ends."""
    result = run(spec(tmp_path, *three_branches("activationCount &gt;= 2")))
    assert starts(result, "E") == [2.0]
    assert completed_at(result) == [3.0]


def test_discriminator_resets_in_a_loop_and_fires_once_per_iteration(tmp_path: Path) -> None:
    """WCP9 once all incoming branches have been triggered it resets, so it can fire again."""
    acts, trans = three_branches("activationCount &gt;= 1")
    acts[0] = activity("A", split="Parallel", join="Exclusive")
    acts.append(activity("S"))
    acts.append(activity("L", route='GatewayType="Exclusive"', split="Exclusive"))
    acts.append(activity("Z"))
    trans = [transition("S", "A"), *trans, transition("E", "L"),
             transition("L", "A", "n &lt; 2"), transition("L", "Z", "otherwise")]
    counting = activity("E", extra='<Assignments><Assignment><Target>n</Target>'
                        '<Expression>n + 1</Expression></Assignment></Assignments>')
    acts[5] = counting
    result = run(spec(tmp_path, acts, trans, integer_field("n", 0)))
    # Iteration 1 fires at t=1 (B) and loops back at once. Iteration 2's B arrives at t=2,
    # but the join still waits for iteration 1's D (t=3) to reset: it fires at t=3 with the
    # token B left waiting; iteration 2's last branch D ends at t=1+3.
    assert starts(result, "E") == [1.0, 3.0]
    assert starts(result, "Z") == [3.0]
    assert completed_at(result) == [4.0]


def test_complex_join_without_an_incoming_condition_is_refused_at_its_line(
        tmp_path: Path) -> None:
    acts, trans = three_branches("x")
    acts[4] = activity("J", join="Complex", route='GatewayType="Complex"')
    path = spec(tmp_path, acts, trans)
    problems = [d for d in check_package(load_spec(path)) if d.severity.value == "error"]
    assert [d.code for d in problems] == ["complex-join-without-condition"]
    assert problems[0].location is not None and problems[0].location.line == 2
    with pytest.raises(SpecError, match="Complex join"):
        run(path)


# --------------------------------------------------------------------- conditional flows
def test_conditional_flows_without_a_split_take_every_transition_whose_condition_holds(
        tmp_path: Path) -> None:
    """BPMN 2.0 §13.2: an activity's outgoing conditional sequence flows are each taken when
    their condition holds; the default (OTHERWISE) only when none does."""
    acts = [activity("A"), activity("B"), activity("C"), activity("D")]
    trans = [transition("A", "B", "x &gt; 0"), transition("A", "C", "x &gt; 1"),
             transition("A", "D", "otherwise")]
    result = run(spec(tmp_path, acts, trans, integer_field("x", 5)))
    assert (starts(result, "B"), starts(result, "C"), starts(result, "D")) == ([0.0], [0.0], [])
    result = run(spec(tmp_path, acts, trans, integer_field("x", -1)))
    assert (starts(result, "B"), starts(result, "C"), starts(result, "D")) == ([], [], [0.0])


# --------------------------------------------------------------------- multi-instance
def mi(ordering: str, flow: str = "All", count: str = "3", complex_condition: str = "",
       seconds: float = 1.0) -> str:
    extra = (f'<Loop LoopType="MultiInstance"><LoopMultiInstance MI_Condition="{count}" '
             f'MI_Ordering="{ordering}" MI_FlowCondition="{flow}"'
             + (f' ComplexMI_FlowCondition="{complex_condition}"' if complex_condition else "")
             + "/></Loop>")
    return activity("M", seconds=seconds, extra=extra)


def mi_run(tmp_path: Path, loop: str, fields: str = "") -> RunResult:
    return run(spec(tmp_path, [activity("S"), loop, activity("N")],
                    [transition("S", "M"), transition("M", "N")], fields))


def completions(result: RunResult, aid: str) -> list[float]:
    assert result.trace is not None
    return [e.time for e in result.trace
            if e.kind == "activity.completed" and e.activity == aid]


def test_parallel_multi_instance_runs_n_instances_at_once_and_synchronises(
        tmp_path: Path) -> None:
    """WCP13 (MI with design-time knowledge), MI_FlowCondition All: N concurrent instances,
    the flow goes on once, after the last."""
    result = mi_run(tmp_path, mi("Parallel"))
    assert starts(result, "M") == [0.0, 0.0, 0.0]
    assert completions(result, "M") == [1.0, 1.0, 1.0]
    assert starts(result, "N") == [1.0]
    assert completed_at(result) == [1.0]


def test_sequential_multi_instance_runs_its_instances_one_after_another(
        tmp_path: Path) -> None:
    result = mi_run(tmp_path, mi("Sequential"))
    assert starts(result, "M") == [0.0, 1.0, 2.0]
    assert starts(result, "N") == [3.0]


def test_multi_instance_count_comes_from_data_at_run_time(tmp_path: Path) -> None:
    """WCP14 (MI with a priori run-time knowledge): the number is read when the activity
    starts."""
    result = mi_run(tmp_path, mi("Parallel", count="n + 1"), integer_field("n", 4))
    assert len(starts(result, "M")) == 5
    assert starts(result, "N") == [1.0]


def test_multi_instance_with_flow_condition_none_passes_a_token_per_instance(
        tmp_path: Path) -> None:
    """WCP12 (MI without synchronisation): every instance continues the flow by itself."""
    result = mi_run(tmp_path, mi("Sequential", flow="None"))
    assert starts(result, "N") == [1.0, 2.0, 3.0]
    assert completed_at(result) == [3.0]


def test_multi_instance_with_flow_condition_one_goes_on_after_the_first(
        tmp_path: Path) -> None:
    result = mi_run(tmp_path, mi("Sequential", flow="One"))
    assert starts(result, "N") == [1.0]
    assert starts(result, "M") == [0.0, 1.0, 2.0]       # the others still run
    assert completed_at(result) == [3.0]


def test_multi_instance_with_a_complex_flow_condition_goes_on_once_it_holds(
        tmp_path: Path) -> None:
    result = mi_run(tmp_path, mi("Sequential", flow="Complex",
                                 complex_condition="nrOfCompletedInstances &gt;= 2"))
    assert starts(result, "N") == [2.0]
    assert completed_at(result) == [3.0]


def test_multi_instance_with_zero_instances_goes_straight_on(tmp_path: Path) -> None:
    result = mi_run(tmp_path, mi("Parallel", count="0"))
    assert starts(result, "N") == [0.0]
    assert completed_at(result) == [0.0]


def test_a_negative_instance_count_aborts_the_instance_with_a_located_fault(
        tmp_path: Path) -> None:
    result = mi_run(tmp_path, mi("Parallel", count="0 - 2"))
    assert starts(result, "N") == []
    [fault] = result.summary["faults"]
    assert "routing.xpdl:2" in fault["message"] and "MI_Condition gave -2" in fault["message"]


# --------------------------------------------------------------------- implicit termination
def test_implicit_termination_ends_a_path_and_the_case_when_no_path_is_left(
        tmp_path: Path) -> None:
    """WCP11: a path that reaches an activity with no outgoing transition ends there; the
    parallel work goes on; the case completes when nothing is left to do."""
    acts = [activity("A", split="Parallel"), activity("B"), activity("C", seconds=5),
            activity("D")]
    trans = [transition("A", "B"), transition("A", "C"), transition("C", "D")]
    result = run(spec(tmp_path, acts, trans), until=None)
    assert starts(result, "B") == [0.0]
    assert starts(result, "D") == [5.0]
    assert completed_at(result) == [5.0]
    assert result.summary["instances"]["open"] == 0


def test_a_path_whose_conditions_all_fail_ends_there_without_a_declared_split(
        tmp_path: Path) -> None:
    """JaWE's implicit-termination sample: a conditional transition out of an activity
    with no split (or an AND split) that does not hold ends that path; the case completes
    when the other paths do. A declared XOR split with nothing to take still aborts."""
    acts = [activity("A", split="Parallel"), activity("B"), activity("C", seconds=2),
            activity("D")]
    trans = [transition("A", "B", "x &gt; 0"), transition("A", "C"),
             transition("C", "D", "x &gt; 0")]
    result = run(spec(tmp_path, acts, trans, integer_field("x", 0)), until=None)
    assert (starts(result, "B"), starts(result, "C"), starts(result, "D")) == ([], [0.0], [])
    assert completed_at(result) == [2.0]
    assert result.summary["faults"] == []
    acts[2] = activity("C", seconds=2, split="Exclusive")
    result = run(spec(tmp_path, acts, trans, integer_field("x", 0)), until=None)
    [fault] = result.summary["faults"]
    assert "no outgoing transition can be taken" in fault["message"]


P17 = Path(__file__).parents[1] / "patterns" / "specs" / "p17_interleaved_parallel_routing.xpdl"


@pytest.mark.parametrize(("ordering", "b_c_d", "e"), [
    ("Sequential", ([1.0], [2.0], []), [4.0]),
    ("Parallel", ([1.0], [1.0], [1.0]), [3.0]),
])
def test_an_ad_hoc_set_stops_when_its_completion_condition_holds(
        tmp_path: Path, ordering: str, b_c_d: tuple[list[float], ...], e: list[float]) -> None:
    """BPMN 2.0 ad-hoc subprocess: the completion condition is checked after each inner
    activity; when it holds the rest is cancelled (running) or never started."""
    text = P17.read_text().replace('AdHocCompletionCondition="done_n == 3"',
                                   'AdHocCompletionCondition="done_n == 2"')
    text = text.replace('AdHocOrdering="Sequential"', f'AdHocOrdering="{ordering}"')
    path = tmp_path / "adhoc.xpdl"
    path.write_text(text)
    result = run(path, until=None)
    assert (starts(result, "B"), starts(result, "C"), starts(result, "D")) == b_c_d
    assert starts(result, "E") == e
    withdrawn_or_stopped = [ev.activity for ev in result.trace or ()
                            if ev.kind == "activity.completed" and ev.activity == "D"]
    assert withdrawn_or_stopped == []
    assert completed_at(result) == [e[0] + 1.0]


def test_a_complex_join_reset_because_nothing_else_can_come_fires_on_the_tokens_it_kept(
        tmp_path: Path) -> None:
    """Iteration 1 fires the discriminator on B; its other branch (via D) never comes (D's
    condition fails and that path ends). Iteration 2's B arrives meanwhile and is kept.
    When nothing is left running, the join resets and fires on it (no deadlock)."""
    acts = [activity("S"), activity("A", split="Parallel", join="Exclusive"),
            activity("B", seconds=1), activity("C", seconds=3), activity("D"),
            activity("J", join="Complex", route='GatewayType="Complex" '
                     'IncomingCondition="activationCount &gt;= 1"'),
            activity("E", extra='<Assignments><Assignment><Target>n</Target>'
                     '<Expression>n + 1</Expression></Assignment></Assignments>'),
            activity("L", route='GatewayType="Exclusive"', split="Exclusive"), activity("Z")]
    trans = [transition("S", "A"), transition("A", "B"), transition("A", "C"),
             transition("B", "J"), transition("C", "D"), transition("D", "J", "n &gt; 100"),
             transition("J", "E"), transition("E", "L"), transition("L", "A", "n &lt; 2"),
             transition("L", "Z", "otherwise")]
    result = run(spec(tmp_path, acts, trans, integer_field("n", 0)), until=None)
    assert starts(result, "E") == [1.0, 4.0]
    assert starts(result, "Z") == [4.0]
    assert result.summary["deadlocks"] == []
    assert completed_at(result) == [4.0]


def labelled_split(tmp_path: Path, performer: str = "") -> Path:
    def label(text: str) -> str:
        return (f'<Condition Type="CONDITION"><Expression ScriptGrammar="Text">{text}'
                "</Expression></Condition>")
    acts = [activity("A"), activity("R", route='GatewayType="Exclusive"', split="Exclusive",
                                    extra=performer), activity("B"), activity("C")]
    trans = [transition("A", "R"),
             f'<Transition Id="to_b" From="R" To="B">{label("Approved")}</Transition>',
             f'<Transition Id="to_c" From="R" To="C">{label("Rejected")}</Transition>']
    return spec(tmp_path, acts, trans)


def test_a_split_between_labelled_branches_takes_one_drawn_from_the_seed(
        tmp_path: Path) -> None:
    """TIBCO's ScriptGrammar="Text" conditions are labels for people: with nobody bound to
    decide, one branch is drawn (reproducibly per seed), never both, never always the first."""
    path = labelled_split(tmp_path)
    taken = []
    for seed in range(20):
        result = Simulation(load_spec(path), keep_trace=True, seed=seed).run()
        b, c = starts(result, "B"), starts(result, "C")
        assert len(b) + len(c) == 1
        taken.append("B" if b else "C")
        again = Simulation(load_spec(path), keep_trace=True, seed=seed).run()
        assert (starts(again, "B"), starts(again, "C")) == (b, c)
    assert set(taken) == {"B", "C"}


def test_a_split_between_labelled_branches_is_offered_to_its_performer(tmp_path: Path) -> None:
    from opspec.engine.builtin_performers import ScriptedUser

    path = labelled_split(tmp_path, "<Performers><Performer>clerk</Performer></Performers>")
    user = ScriptedUser([("at 0", "choose C")])
    result = Simulation(load_spec(path), keep_trace=True,
                        performers={"clerk": user}).run(until=100)
    assert (starts(result, "B"), starts(result, "C")) == ([], [0.0])
    [offer] = [e for e in result.trace or () if e.kind == "activity.offered"]
    assert offer.activity == "R" and offer.data["choices"] == ["B", "C"]
