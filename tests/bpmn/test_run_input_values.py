"""A run input (a variable a diagram's conditions read that the application would set) takes
its value from a data file or a distribution, not only from ``--param NAME=VALUE``
(issue 28: "``run``/``evaluate`` take values (``--param NAME=VALUE``, a data file, a
scenario) or a distribution").

The diagram is Camunda's loan-approval shape: ``${score > 50}`` → ``done``, ``${score <= 50}``
→ ``remind``; one case per simulated user. Expected numbers worked by hand:

- a CSV of four users (20, 70, 45, 90) gives exactly remind, done, remind, done;
- ``score ~ uniform(0, 100)`` on an integer field is rounded, so ``done`` is taken when
  ``U >= 50.5``: p = 0.495 per user, and over n users the count is Binomial(n, 0.495); the
  test accepts the two-sided 99.9 % range of that law (a draw ignored, or the conditions
  bypassed by the 50/50 fallback with a shared value, fails: every user would agree).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from scipy.stats import binom

from opspec.cli import main

USERS = 200

DIAGRAM = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" id="d" targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start"/>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="ask"/>
    <bpmn:exclusiveGateway id="ask" name="Score high?"/>
    <bpmn:sequenceFlow id="yes" sourceRef="ask" targetRef="done">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${score &gt; 50}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="no" sourceRef="ask" targetRef="remind">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${score &lt;= 50}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:endEvent id="done"/>
    <bpmn:endEvent id="remind"/>
  </bpmn:process>
</bpmn:definitions>
"""


@pytest.fixture
def diagram(tmp_path: Path) -> Path:
    path = tmp_path / "loan.bpmn"
    path.write_text(DIAGRAM, encoding="utf-8")
    return path


def _evaluate(diagram: Path, out: Path, *options: str) -> dict[int, str]:
    """The end each simulated user reached, by user index (from the exported trace; no
    report is drawn: tests/evaluate_without_report.py)."""
    from evaluate_without_report import without_report

    with without_report():
        code = main(["evaluate", str(diagram), "--days", "0.001", "--out", str(out),
                     "--export", "jsonl", "--workers", "1", *options])
    assert code == 0
    ends: dict[int, str] = {}
    for line in (out / "traces.jsonl").read_text().splitlines():
        event = json.loads(line)
        if event.get("kind") == "activity.completed" and event["activity"] in ("done",
                                                                                "remind"):
            user = int(event["case"].split("/")[1])           # case A/<user>/p#1
            assert user not in ends                           # one case per user
            ends[user] = event["activity"]
    return ends


def test_a_csv_gives_each_simulated_user_their_row(diagram: Path, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    rows = tmp_path / "users.csv"
    rows.write_text("score\n20\n70\n45\n90\n", encoding="utf-8")
    ends = _evaluate(diagram, tmp_path / "out", "--params", str(rows))  # --users: the rows
    assert ends == {0: "remind", 1: "done", 2: "remind", 3: "done"}
    assert "score from" in capsys.readouterr().out


def test_a_distribution_draws_one_value_per_user_with_the_stated_share(
        diagram: Path, tmp_path: Path) -> None:
    ends = _evaluate(diagram, tmp_path / "one", "--param", "score~uniform(0, 100)",
                     "--users", str(USERS))
    assert len(ends) == USERS
    low, high = binom.interval(0.999, USERS, 0.495)
    assert low <= list(ends.values()).count("done") <= high
    # the same seed gives each user the same value whatever the workers and the users run
    again = _evaluate(diagram, tmp_path / "two", "--param", "score~uniform(0, 100)",
                      "--users", "20", "--workers", "2")
    assert again == {u: ends[u] for u in range(20)}


def test_a_toml_file_gives_values_and_distribution_tables_and_param_wins(
        diagram: Path, tmp_path: Path) -> None:
    table = tmp_path / "inputs.toml"
    table.write_text('score = { kind = "uniform", low = 0, high = 40 }\n', encoding="utf-8")
    ends = _evaluate(diagram, tmp_path / "one", "--params", str(table), "--users", "10")
    assert set(ends.values()) == {"remind"}                  # every draw is at most 40
    fixed = tmp_path / "fixed.toml"
    fixed.write_text("score = 70\n", encoding="utf-8")
    ends = _evaluate(diagram, tmp_path / "two", "--params", str(fixed), "--users", "3")
    assert set(ends.values()) == {"done"}
    ends = _evaluate(diagram, tmp_path / "three", "--params", str(fixed), "--param",
                     "score=10", "--users", "3")
    assert set(ends.values()) == {"remind"}                  # the command line wins


def test_run_takes_a_drawn_value_and_says_it(diagram: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(diagram), "--until", "PT1M", "--json", "--seed", "3",
                 "--param", "score~uniform(0, 100)"]) == 0
    first = json.loads(capsys.readouterr().out)["params"]["score"]
    assert main(["run", str(diagram), "--until", "PT1M", "--json", "--seed", "3",
                 "--param", "score~uniform(0, 100)"]) == 0
    assert json.loads(capsys.readouterr().out)["params"]["score"] == first
    assert isinstance(first, int) and 0 <= first <= 100


def test_a_normal_run_input_is_not_cut_at_zero() -> None:
    """A duration's normal is truncated at 0; a variable's is not (a temperature may be
    below 0): over 200 draws of normal(0, 1) about half are negative."""
    from opspec.run_inputs import RunInputs

    inputs = RunInputs(draws=(("t", {"kind": "normal", "mean": 0.0, "sd": 1.0,
                                     "low": -math.inf}, False),))
    values = [inputs.for_run(7, r)["t"] for r in range(200)]
    low, high = binom.interval(0.999, 200, 0.5)
    assert low <= sum(v < 0 for v in values) <= high
    assert values == [inputs.for_run(7, r)["t"] for r in range(200)]     # seeded


@pytest.mark.parametrize(("content", "name", "options", "said"), [
    ("score\n20\nhigh\n", "users.csv", (), "users.csv:3: score is an integer"),
    ("score\n20\n\n7,8\n", "users.csv", (), "users.csv:4: 2 values for 1 names"),
    ("scor\n20\n", "users.csv", (), "did you mean 'score'"),
    ("score\n20\n30\n", "users.csv", ("--users", "3"), "has 2 rows, one per simulated user"),
    ('score = { kind = "unifrom", low = 0 }\n', "inputs.toml", (), "unknown distribution"),
    ("score = [1, 2]\n", "inputs.toml", (), "a value or a distribution table is expected"),
    ("score: 1\n", "inputs.yaml", (), "opspec reads .toml, .json or .csv files"),
    ('{"score": "a\tb"}', "inputs.json", (),
     "inputs.json:1: not valid JSON: Invalid control character at column 13"),
    ("", "none.csv", ("--param", "score~bogus(1)"), "unknown distribution 'bogus'"),
])
def test_bad_values_are_refused_naming_the_file_and_line(
        diagram: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], content: str,
        name: str, options: tuple[str, ...], said: str) -> None:
    path = tmp_path / name
    path.write_text(content, encoding="utf-8")
    given = ("--params", str(path)) if content else ()
    code = main(["evaluate", str(diagram), "--days", "0.001", "--out", str(tmp_path / "out"),
                 *given, *options])
    err = capsys.readouterr().err
    assert code == 2 and said in err, err
    assert "Traceback" not in err


def test_a_json_list_gives_rows_and_a_swept_drawn_input_is_refused(
        diagram: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rows = tmp_path / "users.json"
    rows.write_text('[{"score": 80}, {"score": 10}]', encoding="utf-8")
    assert _evaluate(diagram, tmp_path / "out", "--params", str(rows)) == {0: "done",
                                                                           1: "remind"}
    code = main(["evaluate", str(diagram), "--days", "0.001", "--out", str(tmp_path / "sw"),
                 "--param", "score~uniform(0, 100)", "--sweep", "spec.score=10,90"])
    err = capsys.readouterr().err
    assert code == 2 and "would override every swept value" in err
