"""Gateways a modeller's diagram leaves undecided are decided by branch probabilities —
declared (opspec:Probability, BPSim, QBP) or, said at the gateway's line, equal — never by
the order of the flows in the file; every draw is a ``branch.chosen`` trace event.

The expected shares are worked by hand: with a probability p per instance and n independent
instances, the count taken is Binomial(n, p); the tests accept the counts inside the
two-sided 99.9 % range of that law (from scipy), so a wrong share (the file's first flow
every time, p and 1 - p swapped, a share ignored) fails while the seeded draw passes.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest
from scipy.stats import binom

import opspec
from opspec.errors import Severity
from opspec.xpdl.namespaces import OPSPEC
from opspec.xpdl.validate import validate_spec

N = 400          # instances: a timer start every minute for 400 minutes

BPMN_NS = 'xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"'
OPSPEC_NS = f'xmlns:opspec="{OPSPEC}"'


def _diagram(gateway: str = "exclusiveGateway", yes: str = "", no: str = "",
             extra_root: str = "", extra_ns: str = "") -> str:
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions {BPMN_NS} {OPSPEC_NS} {extra_ns} id="d" targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start">
      <bpmn:timerEventDefinition><bpmn:timeCycle>R{N}/PT1M</bpmn:timeCycle></bpmn:timerEventDefinition>
    </bpmn:startEvent>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="ask"/>
    <bpmn:{gateway} id="ask" name="Pill taken?"/>
    <bpmn:sequenceFlow id="yes" name="Yes" sourceRef="ask" targetRef="done">{yes}</bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="no" name="No" sourceRef="ask" targetRef="remind">{no}</bpmn:sequenceFlow>
    <bpmn:endEvent id="done"/>
    <bpmn:endEvent id="remind"/>
  </bpmn:process>{extra_root}
</bpmn:definitions>
"""


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "diagram.bpmn"
    path.write_text(text, encoding="utf-8")
    return path


def _choices(path: Path, seed: int = 1) -> Counter[str]:
    outcome = opspec.run(path, seed=seed, until=(N + 1) * 60)
    return Counter(e.data["flow"] for e in outcome.trace if e.kind == "branch.chosen")


def _diagnostics(path: Path, code: str) -> list[tuple[Severity, int | None, str]]:
    _package, report = validate_spec(path)
    return [(d.severity, d.location.line, d.message) for d in report.diagnostics
            if d.code == code]


def _inside(count: int, p: float) -> bool:
    low, high = binom.interval(0.999, N, p)
    return low <= count <= high


def test_a_yes_no_gateway_without_conditions_is_drawn_evenly_and_said_at_its_line(
        tmp_path: Path) -> None:
    path = _write(tmp_path, _diagram())
    warnings = _diagnostics(path, "undecided-gateway")
    assert len(warnings) == 1
    severity, line, message = warnings[0]
    assert severity is Severity.WARNING and line == 8      # the gateway's own line
    assert "only labels" in message and "yes 50 %" in message and "no 50 %" in message
    counts = _choices(path)
    assert sum(counts.values()) == N                       # one draw per instance
    assert _inside(counts["yes"], 0.5) and _inside(counts["no"], 0.5)


def test_opspec_probability_on_the_flows_decides_the_shares(tmp_path: Path) -> None:
    yes = '<bpmn:extensionElements><opspec:Probability Value="0.8"/></bpmn:extensionElements>'
    path = _write(tmp_path, _diagram(yes=yes))          # "no" gets what is left: 0.2
    assert not _diagnostics(path, "undecided-gateway")
    assert _diagnostics(path, "branch-probabilities")
    counts = _choices(path)
    assert _inside(counts["yes"], 0.8) and _inside(counts["no"], 0.2)
    assert not _inside(counts["yes"], 0.5)                 # the declared share, not the even one


BPSIM = """
  <bpmn:relationship type="BPSimData">
    <bpmn:extensionElements>
      <bpsim:BPSimData>
        <bpsim:Scenario id="default" name="Scenario">
          <bpsim:ElementParameters elementRef="yes">
            <bpsim:ControlParameters>
              <bpsim:Probability><bpsim:FloatingParameter value="0.1"/></bpsim:Probability>
            </bpsim:ControlParameters>
          </bpsim:ElementParameters>
          <bpsim:ElementParameters elementRef="no">
            <bpsim:ControlParameters>
              <bpsim:Probability><bpsim:FloatingParameter value="0.9"/></bpsim:Probability>
            </bpsim:ControlParameters>
          </bpsim:ElementParameters>
        </bpsim:Scenario>
      </bpsim:BPSimData>
    </bpmn:extensionElements>
    <bpmn:source>d</bpmn:source>
    <bpmn:target>d</bpmn:target>
  </bpmn:relationship>"""


@pytest.mark.parametrize("version", ["1.0", "2.0"])
def test_a_bpsim_scenario_gives_the_branch_probabilities(tmp_path: Path, version: str) -> None:
    path = _write(tmp_path, _diagram(
        extra_root=BPSIM, extra_ns=f'xmlns:bpsim="http://www.bpsim.org/schemas/{version}"'))
    infos = _diagnostics(path, "branch-probabilities")
    assert infos and "BPSim" in infos[0][2]
    assert not _diagnostics(path, "unsupported-element")   # the relationship is read, not ignored
    counts = _choices(path)
    assert _inside(counts["yes"], 0.1) and _inside(counts["no"], 0.9)


QBP = """
  <qbp:processSimulationInfo id="qbp_1" processInstances="100" startDateTime="2026-01-01T09:00:00">
    <qbp:sequenceFlows>
      <qbp:sequenceFlow elementId="yes" executionProbability="0.3"/>
      <qbp:sequenceFlow elementId="no" executionProbability="0.7"/>
    </qbp:sequenceFlows>
  </qbp:processSimulationInfo>"""


def test_a_qbp_simulation_info_gives_the_branch_probabilities(tmp_path: Path) -> None:
    path = _write(tmp_path, _diagram(
        extra_root=QBP, extra_ns='xmlns:qbp="http://www.qbp-simulator.com/Schema201212"'))
    assert "QBP" in _diagnostics(path, "branch-probabilities")[0][2]
    counts = _choices(path)
    assert _inside(counts["yes"], 0.3) and _inside(counts["no"], 0.7)


def test_probabilities_over_one_are_refused_at_the_gateway(tmp_path: Path) -> None:
    yes = '<bpmn:extensionElements><opspec:Probability Value="1.5"/></bpmn:extensionElements>'
    path = _write(tmp_path, _diagram(yes=yes))
    errors = _diagnostics(path, "bad-probability")
    assert errors and errors[0][0] is Severity.ERROR and "1.5" in errors[0][2]


def test_an_inclusive_gateway_takes_each_flow_with_its_own_probability(tmp_path: Path) -> None:
    yes = '<bpmn:extensionElements><opspec:Probability Value="0.5"/></bpmn:extensionElements>'
    no = '<bpmn:extensionElements><opspec:Probability Value="0.5"/></bpmn:extensionElements>'
    path = _write(tmp_path, _diagram(gateway="inclusiveGateway", yes=yes, no=no))
    counts = _choices(path)
    # each flow independently with 1/2, drawn again when neither is taken: the subsets
    # {yes}, {no}, {yes, no} are equally likely, so each flow is taken with 2/3
    assert _inside(counts["yes"], 2 / 3) and _inside(counts["no"], 2 / 3)
    assert sum(counts.values()) > N                          # some instances took both


def test_the_same_seed_gives_the_same_decisions_and_another_seed_others(tmp_path: Path) -> None:
    path = _write(tmp_path, _diagram())
    first = [e.data["flow"] for e in opspec.run(path, seed=5, until=3600).trace
             if e.kind == "branch.chosen"]
    again = [e.data["flow"] for e in opspec.run(path, seed=5, until=3600).trace
             if e.kind == "branch.chosen"]
    other = [e.data["flow"] for e in opspec.run(path, seed=6, until=3600).trace
             if e.kind == "branch.chosen"]
    assert first == again and first != other


def test_a_loop_through_an_undecided_gateway_ends_instead_of_spinning(tmp_path: Path) -> None:
    """A "try again?" loop drawn with labels only: with the file's first flow taken every time
    (BPMN's reading of unconditioned flows) it would spin at one instant; drawn with
    probability 1/2 per pass, the number of passes is geometric with mean 2."""
    text = f"""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions {BPMN_NS} id="d" targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start">
      <bpmn:timerEventDefinition><bpmn:timeCycle>R{N}/PT1H</bpmn:timeCycle></bpmn:timerEventDefinition>
    </bpmn:startEvent>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="merge"/>
    <bpmn:exclusiveGateway id="merge"/>
    <bpmn:sequenceFlow id="f1" sourceRef="merge" targetRef="try"/>
    <bpmn:scriptTask id="try"><bpmn:script>n = 1</bpmn:script></bpmn:scriptTask>
    <bpmn:sequenceFlow id="f2" sourceRef="try" targetRef="again"/>
    <bpmn:exclusiveGateway id="again" name="Again?"/>
    <bpmn:sequenceFlow id="retry" name="Yes" sourceRef="again" targetRef="merge"/>
    <bpmn:sequenceFlow id="stop" name="No" sourceRef="again" targetRef="end"/>
    <bpmn:endEvent id="end"/>
  </bpmn:process>
</bpmn:definitions>
"""
    path = _write(tmp_path, text)
    outcome = opspec.run(path, seed=2, until=(N + 1) * 3600)
    passes = sum(1 for e in outcome.trace if e.kind == "activity.completed"
                 and e.activity == "try")
    ends = sum(1 for e in outcome.trace if e.kind == "activity.completed"
               and e.activity == "end")
    assert ends == N
    # passes = N + (retries); retries ~ NegBinomial(N, 1/2): mean N, sd sqrt(2N) ~ 28
    assert N + N - 4 * 28 <= passes <= N + N + 4 * 28


def test_duplicate_ids_inside_a_modellers_extension_data_do_not_refuse_the_diagram(
        tmp_path: Path) -> None:
    vendor = ('<bpmn:extensionElements><vp:data xmlns:vp="http://vp.example/ext">'
              '<bpmn:documentation id="same"/><bpmn:documentation id="same"/>'
              '</vp:data></bpmn:extensionElements>')
    text = _diagram().replace('<bpmn:endEvent id="done"/>',
                              f'<bpmn:endEvent id="done">{vendor}</bpmn:endEvent>')
    path = _write(tmp_path, text)
    assert not _diagnostics(path, "duplicate-id")
    # a repeated id among the model's own elements is still refused
    twice = _diagram().replace('<bpmn:endEvent id="remind"/>',
                               '<bpmn:endEvent id="remind"/><bpmn:endEvent id="done"/>')
    assert _diagnostics(_write(tmp_path, twice), "duplicate-id")


def test_the_probabilities_survive_conversion_to_xpdl(tmp_path: Path) -> None:
    from opspec.xpdl.loader import load_spec
    from opspec.xpdl.writer import write_xpdl

    yes = '<bpmn:extensionElements><opspec:Probability Value="0.8"/></bpmn:extensionElements>'
    path = _write(tmp_path, _diagram(yes=yes))
    xpdl = tmp_path / "diagram.xpdl"
    xpdl.write_bytes(write_xpdl(load_spec(path)))
    again = load_spec(xpdl)
    shares = {t.id: t.probability for t in again.processes[0].transitions if t.source == "ask"}
    assert shares == pytest.approx({"yes": 0.8, "no": 0.2})
    counts = _choices(xpdl)
    assert _inside(counts["yes"], 0.8)


CAMUNDA_NS = 'xmlns:camunda="http://camunda.org/schema/1.0/bpmn"'


def _scored(tmp_path: Path) -> Path:
    """Camunda's loan-approval shape: the application sets ``score`` at run time."""
    yes = ('<bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${score &gt; 50}'
           '</bpmn:conditionExpression>')
    no = ('<bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${score &lt;= 50}'
          '</bpmn:conditionExpression>')
    text = _diagram(yes=yes, no=no, extra_ns=CAMUNDA_NS +
                    ' xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"')
    return _write(tmp_path, text)


def test_a_variable_the_application_sets_is_a_run_input_not_an_error(tmp_path: Path) -> None:
    path = _scored(tmp_path)
    _package, report = validate_spec(path)
    assert not [d for d in report.diagnostics if d.severity is Severity.ERROR]
    inputs = _diagnostics(path, "run-input")
    assert len(inputs) == 1 and "'score'" in inputs[0][2] and inputs[0][1] == 9      # the flow whose condition reads it
    gateway = _diagnostics(path, "undecided-gateway")
    assert gateway and gateway[0][1] == 8 and "score" in gateway[0][2]


def test_a_run_input_given_decides_by_the_conditions(tmp_path: Path) -> None:
    path = _scored(tmp_path)
    high = opspec.run(path, seed=1, until=3600, params={"score": 70})
    low = opspec.run(path, seed=1, until=3600, params={"score": 20})
    taken_high = {e.activity for e in high.trace if e.kind == "activity.completed"}
    taken_low = {e.activity for e in low.trace if e.kind == "activity.completed"}
    assert "done" in taken_high and "remind" not in taken_high
    assert "remind" in taken_low and "done" not in taken_low
    assert not [e for e in high.trace if e.kind == "branch.chosen"]


def test_a_run_input_not_given_is_drawn_at_random_and_traced(tmp_path: Path) -> None:
    counts = _choices(_scored(tmp_path))
    assert _inside(counts["yes"], 0.5) and _inside(counts["no"], 0.5)


def test_param_on_the_command_line_gives_a_run_input_typed_and_checked(tmp_path: Path) -> None:
    import json
    import subprocess
    import sys

    path = _scored(tmp_path)

    def run(*options: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "opspec", "run", str(path), "--until",
                               "PT1H", "--json", *options], capture_output=True, text=True,
                              timeout=120)

    trace = tmp_path / "trace.jsonl"
    given = run("--param", "score=70", "--trace", str(trace))
    assert given.returncode == 0, given.stderr
    assert json.loads(given.stdout)["instances"]["completed"] == 59    # one a minute
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    completed = {e.get("activity") for e in events if e.get("kind") == "activity.completed"}
    assert "done" in completed and "remind" not in completed      # score 70 > 50
    assert not [e for e in events if e.get("kind") == "branch.chosen"]
    misspelt = run("--param", "scor=70")
    assert misspelt.returncode == 2 and "did you mean 'score'" in misspelt.stderr
    assert "Traceback" not in misspelt.stderr
    wrong_type = run("--param", "score=high")
    assert wrong_type.returncode == 2 and "score is an integer" in wrong_type.stderr


def test_evaluate_param_gives_every_simulated_user_the_run_input(tmp_path: Path) -> None:
    import json

    from opspec.cli import main

    path = _scored(tmp_path)
    out = tmp_path / "evaluation"
    code = main(["evaluate", str(path), "--param", "score=20", "--users", "3", "--days",
                 "0.01", "--out", str(out), "--export", "jsonl", "--workers", "1"])
    assert code == 0
    events = [json.loads(line) for line in (out / "traces.jsonl").read_text().splitlines()]
    completed = [e.get("activity") for e in events if e.get("kind") == "activity.completed"]
    asked = completed.count("ask")
    assert asked >= 3 * 10                                    # one a minute, 14.4 minutes
    assert completed.count("remind") == asked and "done" not in completed   # 20 <= 50
    assert not [e for e in events if e.get("kind") == "branch.chosen"]


def test_a_scenario_file_gives_a_run_input_in_its_given_params(tmp_path: Path) -> None:
    from opspec.testing.scenario import load_scenarios, run_scenario

    _scored(tmp_path)
    (tmp_path / "loan.scenario.toml").write_text('''spec = "diagram.bpmn"

[[scenario]]
name = "a high score is never reminded"
given = { params = { score = 70 }, until = "PT10M" }
then = ["never activity remind"]

[[scenario]]
name = "a low score is never done"
given = { params = { score = 20 }, until = "PT10M" }
then = ["never activity done"]

[[scenario]]
name = "a low score said to be never reminded fails"
given = { params = { score = 20 }, until = "PT10M" }
then = ["never activity remind"]
''', encoding="utf-8")
    document = load_scenarios(tmp_path / "loan.scenario.toml")
    spec = tmp_path / "diagram.bpmn"
    outcomes = [run_scenario(s, spec, seed=1) for s in document.scenarios]
    assert outcomes[0] == [] and outcomes[1] == []
    assert outcomes[2]                       # the conditions decided: remind happened
