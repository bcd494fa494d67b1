"""Branch probabilities given at run time (issue 28: undecided gateway choices are decided by
declared branch probabilities "read from the file ... or given at run time (a scenario or
``--param``/``--branch`` option)"): ``--branch``, ``opspec.run(branches=...)`` and a scenario's
``given.branches`` replace the file's probabilities of an undecided gateway.

The diagram's gateway "Pill taken?" has flows labelled Yes and No and no condition, so the
file alone draws them 50/50. Expected numbers worked by hand: with ``--branch`` Yes 0.8 over
N = 400 instances the count of Yes is Binomial(400, 0.8) (mean 320, sd 8); its exact two-sided
99.9 % range is 293..345 (P(X <= 292) = 0.00045, P(X >= 346) = 0.00027, each under 0.0005).
The file's 50/50 (about 200) and a swapped 0.2 (about 80) both fall far outside it.
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest

import opspec
from opspec.cli import main
from opspec.errors import ConfigurationError
from opspec.testing.scenario import load_scenarios, run_scenario

N = 400

DIAGRAM = f"""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" id="d" targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start">
      <bpmn:timerEventDefinition><bpmn:timeCycle>R{N}/PT1M</bpmn:timeCycle></bpmn:timerEventDefinition>
    </bpmn:startEvent>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="ask"/>
    <bpmn:exclusiveGateway id="ask" name="Pill taken?"/>
    <bpmn:sequenceFlow id="yes" name="Yes" sourceRef="ask" targetRef="done"/>
    <bpmn:sequenceFlow id="no" name="No" sourceRef="ask" targetRef="check"/>
    <bpmn:exclusiveGateway id="check" name="Score high?"/>
    <bpmn:sequenceFlow id="high" sourceRef="check" targetRef="done2">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${{1 &gt; 0}}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="low" sourceRef="check" targetRef="remind">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${{1 &lt;= 0}}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:endEvent id="done"/>
    <bpmn:endEvent id="done2"/>
    <bpmn:endEvent id="remind"/>
  </bpmn:process>
</bpmn:definitions>
"""


@pytest.fixture
def diagram(tmp_path: Path) -> Path:
    path = tmp_path / "pill.bpmn"
    path.write_text(DIAGRAM, encoding="utf-8")
    return path


def _choices(diagram: Path, branches: dict[str, dict[str, float]] | None, seed: int = 1
             ) -> Counter[str]:
    outcome = opspec.run(diagram, seed=seed, until=(N + 1) * 60, branches=branches)
    return Counter(e.data["flow"] for e in outcome.trace if e.kind == "branch.chosen")


def test_a_run_time_share_replaces_the_files_even_draw(diagram: Path) -> None:
    counts = _choices(diagram, {"Pill taken?": {"Yes": 0.8, "No": 0.2}})
    assert sum(counts.values()) == N
    assert 293 <= counts["yes"] <= 345, counts


def test_a_flow_left_out_takes_the_rest_and_a_share_of_one_is_always_taken(
        diagram: Path) -> None:
    assert _choices(diagram, {"ask": {"no": 0.0}}) == Counter(yes=N)
    assert _choices(diagram, {"ask": {"No": "100%"}}) == Counter(no=N)  # type: ignore[dict-item]


def test_the_cli_option_reaches_the_trace(diagram: Path, tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    trace = tmp_path / "t.jsonl"
    assert main(["run", str(diagram), "--until", str((N + 1) * 60), "--timeline", "none",
                 "--trace", str(trace), "--branch", "Pill taken?=Yes:1"]) == 0
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    flows = [e["data"]["flow"] for e in events if e.get("kind") == "branch.chosen"]
    assert flows == ["yes"] * N
    # the file's warning about the 50/50 it would have drawn no longer applies
    assert "equal probabilities" not in capsys.readouterr().err


def test_evaluate_draws_the_same_branches_whatever_the_number_of_workers(
        diagram: Path, tmp_path: Path, no_report) -> None:
    # the exported trace is the point: no report (tests/evaluate_without_report.py)
    def chosen(workers: str) -> list[str]:
        out = tmp_path / f"w{workers}"
        assert main(["evaluate", str(diagram), "--users", "4", "--days", "0.01", "--out",
                     str(out), "--export", "jsonl", "--workers", workers, "--seed", "5",
                     "--branch", "ask=yes:0.3,no:0.7"]) == 0
        events = [json.loads(line) for line in (out / "traces.jsonl").read_text().splitlines()]
        return sorted(f"{e['case']} {e['time']} {e['data']['flow']}" for e in events
                      if e.get("kind") == "branch.chosen")

    one = chosen("1")
    assert len(one) == 4 * 14 and {"yes", "no"} <= {line.rsplit(" ", 1)[1] for line in one}
    assert chosen("2") == one


@pytest.mark.parametrize(("option", "said"), [
    ("Pill takn?=Yes:0.8,No:0.2", "did you mean 'Pill taken?'"),
    ("ask=Yess:0.8,No:0.2", "did you mean 'Yes'"),
    ("ask=Yes:0.8,No:0.3", "sum to 1.1, not 1"),
    ("ask=Yes:1.5", "is not a probability"),
    ("ask=Yes", "is not FLOW:P"),
    ("check=high:0.5,low:0.5", "conditions of check ('Score high?') decide it"),
])
def test_bad_branch_options_are_refused_before_anything_runs(
        diagram: Path, capsys: pytest.CaptureFixture[str], option: str, said: str) -> None:
    assert main(["run", str(diagram), "--until", "60", "--branch", option]) == 2
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err, err


def test_evaluate_refuses_a_bad_branch_too(diagram: Path, tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["evaluate", str(diagram), "--users", "2", "--days", "0.001", "--out",
                 str(tmp_path / "o"), "--branch", "ask=nope:1"]) == 2
    assert "no flow 'nope'" in capsys.readouterr().err


def test_a_scenario_gives_branches(diagram: Path, tmp_path: Path) -> None:
    scenarios = tmp_path / "pill.scenario.toml"
    scenarios.write_text(f'''spec = "{diagram.name}"

[[scenario]]
name = "always taken"
given = {{ branches = {{ "Pill taken?" = {{ Yes = 1.0, No = 0.0 }} }}, until = "{N}min" }}
then = ["never activity done2"]

[[scenario]]
name = "file's draw"
given = {{ until = "{N}min" }}
then = ["never activity done2"]
''', encoding="utf-8")
    given, plain = load_scenarios(scenarios).scenarios
    assert given.branches == {"Pill taken?": {"Yes": 1.0, "No": 0.0}}
    assert run_scenario(given, diagram) == []
    assert run_scenario(plain, diagram) != []          # 50/50: "No" leads to done2


def test_a_scenario_with_a_bad_branch_table_names_its_key(tmp_path: Path) -> None:
    scenarios = tmp_path / "bad.scenario.toml"
    (tmp_path / "pill.bpmn").write_text(DIAGRAM, encoding="utf-8")
    scenarios.write_text('''spec = "pill.bpmn"

[[scenario]]
name = "x"
given = { branches = { ask = { yes = "lots" } } }
then = ["never activity done2"]
''', encoding="utf-8")
    with pytest.raises(ConfigurationError, match="branches"):
        load_scenarios(scenarios)
