"""A scenario's ``given.params`` and ``given.branches`` name things of the spec (package data
fields; gateways and their flows): a name the spec lacks, or probabilities it cannot take, is a
mistake in the scenario file, refused when the file is collected (as a ``then`` naming an
activity the spec lacks is) at the line of its own key, in the file's words. They were refused
only when the scenario ran, at its ``[[scenario]]`` line, and a branch's message spoke the
command line's ``--branch GATEWAY=FLOW:P``."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.errors import ConfigurationError

#: "Pill taken?" is undecided (labels only); "Score high?" is decided by its conditions over
#: the run input ``score`` (the diagram's one package data field)
DIAGRAM = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" id="d" targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start"/>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="ask"/>
    <bpmn:exclusiveGateway id="ask" name="Pill taken?"/>
    <bpmn:sequenceFlow id="yes" name="Yes" sourceRef="ask" targetRef="done"/>
    <bpmn:sequenceFlow id="no" name="No" sourceRef="ask" targetRef="check"/>
    <bpmn:exclusiveGateway id="check" name="Score high?"/>
    <bpmn:sequenceFlow id="high" sourceRef="check" targetRef="done2">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${score &gt; 50}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="low" sourceRef="check" targetRef="remind">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression">${score &lt;= 50}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:endEvent id="done"/>
    <bpmn:endEvent id="done2"/>
    <bpmn:endEvent id="remind"/>
  </bpmn:process>
</bpmn:definitions>
"""

HEAD = 'spec = "pill.bpmn"\n\n[[scenario]]\nname = "ok"\nthen = ["eventually activity done"]\n'


def _refusal(tmp_path: Path, text: str) -> ConfigurationError:
    from opspec.testing.scenario import load_scenarios

    (tmp_path / "pill.bpmn").write_text(DIAGRAM, encoding="utf-8")
    (tmp_path / "pill.scenario.toml").write_text(text, encoding="utf-8")
    with pytest.raises(ConfigurationError) as raised:
        load_scenarios(tmp_path / "pill.scenario.toml")
    return raised.value


def _said(tmp_path: Path, text: str) -> str:
    said = str(_refusal(tmp_path, text)).removeprefix(str(tmp_path / "pill.scenario.toml"))
    assert "--branch" not in said and "--param" not in said, said   # the file's words
    return said


# ---------------------------------------------------------------- params
def test_a_params_name_the_spec_lacks_is_refused_at_its_line(tmp_path: Path) -> None:
    said = _said(tmp_path, HEAD + (
        '\n[[scenario]]\nname = "high score"\ngiven.until = 60\n'
        'given.params.scroe = 70\nthen = ["eventually activity done"]\n'))
    assert said == (":10: scenario[1].given.params.scroe: the spec has no package data field "
                    "'scroe' (did you mean 'score'?) (its run inputs: score; opspec validate "
                    "lists the run inputs)")


def test_a_params_name_in_an_inline_table_is_placed_at_its_line(tmp_path: Path) -> None:
    said = _said(tmp_path, HEAD + (
        '\n[[scenario]]\nname = "x"\n\n'
        'given = { until = 60, params = { score = 70, level = 3 } }\n'
        'then = ["eventually activity done"]\n'))
    assert said.startswith(":10: scenario[1].given.params.level: the spec has no package data "
                           "field 'level'")


def test_the_file_s_given_params_are_checked_at_their_own_key(tmp_path: Path) -> None:
    said = _said(tmp_path, (
        'spec = "pill.bpmn"\n\n[given]\nuntil = 60\n\n[given.params]\nscore = 70\n'
        '"dose limit" = 2\n\n[[scenario]]\nname = "x"\nthen = ["eventually activity done"]\n'))
    assert said.startswith(':8: given.params."dose limit": the spec has no package data field '
                           "'dose limit'")


def test_a_declared_params_name_is_taken(tmp_path: Path) -> None:
    from opspec.testing.scenario import load_scenarios, run_scenario

    (tmp_path / "pill.bpmn").write_text(DIAGRAM, encoding="utf-8")
    (tmp_path / "pill.scenario.toml").write_text(
        'spec = "pill.bpmn"\n[[scenario]]\nname = "x"\ngiven.until = 60\n'
        'given.params.score = 70\ngiven.branches.ask = { no = 1 }\n'
        'then = ["eventually activity done2", "never activity remind"]\n', encoding="utf-8")
    (scenario,) = load_scenarios(tmp_path / "pill.scenario.toml").scenarios
    assert run_scenario(scenario, tmp_path / "pill.bpmn") == []


# ---------------------------------------------------------------- branches
@pytest.mark.parametrize(("given", "said"), [
    # a gateway the spec lacks: at the gateway's key, quoted as TOML quotes it
    ('given.branches."Pill takn?" = { Yes = 0.8, No = 0.2 }',
     (':9: scenario[1].given.branches."Pill takn?": no gateway of this id or name (did you '
     "mean 'Pill taken?'?); name a gateway by its id or name, as opspec validate prints them "
     "(docs/bpmn.md, Undecided gateways)")),
    # a flow it lacks: at the flow's key
    ('given.branches."Pill taken?" = { Yess = 0.8, No = 0.2 }',
     (':9: scenario[1].given.branches."Pill taken?".Yess: no flow of this id or name out of ask '
     "('Pill taken?') (did you mean 'Yes'?); its flows are yes ('Yes'), no ('No')")),
    # probabilities that do not sum to 1: at the gateway's key, as the table writes them
    ("given.branches.ask = { yes = 0.8, no = 0.3 }",
     (":9: scenario[1].given.branches.ask: yes = 0.8, no = 0.3 sum to 1.1, not 1; an exclusive "
     "gateway's probabilities sum to 1 (or leave one flow out: it takes the rest)")),
    # a gateway its conditions decide: what to give instead, in the file's keys
    ("given.branches.check = { high = 0.5, low = 0.5 }",
     (":9: scenario[1].given.branches.check: the conditions of check ('Score high?') decide "
     "it; branch probabilities apply only to a gateway the diagram leaves undecided; leave it "
     "out of branches, or give the run inputs its conditions read (given.params)")),
    ("given.branches.done = { x = 1 }",
     (":9: scenario[1].given.branches.done: done is not a gateway with a choice of flows (name "
     "an exclusive or inclusive gateway)")),
    # no probability: at the flow's key
    ('given.branches.ask = { yes = "lots" }',
     (":9: scenario[1].given.branches.ask.yes: 'lots' is not a probability; a probability lies "
     "between 0 and 1 (0.8 or 80%)")),
    ("given.branches.ask = 0.8",
     (":9: scenario[1].given.branches.ask: 0.8 is not a table of flows and probabilities "
     "(write { FLOW = 0.8, OTHER = 0.2 })")),
    ("given.branches = 0.8",
     (":9: scenario[1].given.branches: 0.8 is not a table of gateways (write branches = "
     "{ GATEWAY = { FLOW = 0.8, OTHER = 0.2 } })")),
], ids=["gateway", "flow", "sum", "decided", "not-a-choice", "probability", "flows-table",
        "gateways-table"])
def test_a_branch_the_spec_cannot_take_is_refused_at_its_key(
        tmp_path: Path, given: str, said: str) -> None:
    assert _said(tmp_path, HEAD + (
        f'\n[[scenario]]\nname = "x"\n{given}\ngiven.until = 60\n'
        'then = ["eventually activity done"]\n')) == said


def test_a_flow_in_a_table_of_its_own_is_placed_at_its_line(tmp_path: Path) -> None:
    error = _refusal(tmp_path, HEAD + (
        '\n[[scenario]]\nname = "x"\ngiven.until = 60\nthen = ["eventually activity done"]\n'
        '\n[scenario.given.branches."Pill taken?"]\nYes = 0.75\nNo = 0.25\nMaybe = 0\n'))
    at = error.location
    assert at is not None
    assert (at.line, at.key) == (15, 'scenario[1].given.branches."Pill taken?".Maybe')


def test_the_file_s_given_branches_are_checked_at_their_own_key(tmp_path: Path) -> None:
    said = _said(tmp_path, (
        'spec = "pill.bpmn"\n\n[given]\nuntil = 60\nbranches.ask = { yes = 0.5 }\n'
        'branches.Ask = { yes = 0.5 }\n\n[[scenario]]\nname = "x"\n'
        'then = ["eventually activity done"]\n'))
    assert said.startswith(":6: given.branches.Ask: no gateway of this id or name (did you "
                           "mean 'ask'?)")


# ---------------------------------------------------------------- through pytest
def test_collecting_the_file_is_the_error(pytester: pytest.Pytester) -> None:
    # the file is wrong, as with any other key of it: no scenario of it runs
    (pytester.path / "pill.bpmn").write_text(DIAGRAM, encoding="utf-8")
    (pytester.path / "pill.scenario.toml").write_text(HEAD + (
        '\n[[scenario]]\nname = "x"\ngiven.until = 60\n'
        'given.branches."Pill taken?" = { Yes = 0.8, Nope = 0.2 }\n'
        'then = ["eventually activity done"]\n'), encoding="utf-8")
    result = pytester.runpytest()
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines(["*ERROR collecting pill.scenario.toml*", (
        'bad scenario file: pill.scenario.toml:10: scenario?1?.given.branches."Pill taken?".Nope:'
        " no flow of this id or name out of ask ('Pill taken?')*")])
    assert "--branch" not in result.stdout.str()
