"""A refusal of branch probabilities is said in the words of where they were given: on the
command line (``--branch GATEWAY: …``, a hint in its syntax) as before, and for a file's
``{GATEWAY = {FLOW = P}}`` table (a scenario's ``given.branches``) without the command line's
syntax, with the keys below the table it is about (``BranchRefusal.at``), so that the file
places it at their line (tests/testing_plugin/test_scenario_given_names.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.branch_choices import (
    BranchRefusal,
    check_branch_table,
    read_branch_table,
    with_branches,
)
from opspec.runs import open_gated

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


@pytest.fixture(scope="module")
def package(tmp_path_factory: pytest.TempPathFactory) -> object:
    path = Path(tmp_path_factory.mktemp("branches")) / "pill.bpmn"
    path.write_text(DIAGRAM, encoding="utf-8")
    return open_gated(path)[0]


@pytest.mark.parametrize(("branches", "cli", "at", "in_file"), [
    ({"Pill takn?": {"Yes": 0.8}},
     ("--branch Pill takn?: no gateway of this id or name (did you mean 'Pill taken?'?); write "
     "GATEWAY=FLOW:P[,FLOW:P...], e.g. --branch \"Pill taken?=Yes:0.8,No:0.2\" (docs/bpmn.md, "
     "Undecided gateways)"),
     ("Pill takn?",), ("no gateway of this id or name (did you mean 'Pill taken?'?); name a "
     "gateway by its id or name, as opspec validate prints them (docs/bpmn.md, Undecided "
     "gateways)")),
    ({"ask": {"Yess": 0.8, "No": 0.2}},
     ("--branch ask: no flow 'Yess' out of it (did you mean 'Yes'?); its flows are yes ('Yes'), "
     "no ('No')"),
     ("ask", "Yess"), ("no flow of this id or name out of ask ('Pill taken?') (did you mean "
     "'Yes'?); its flows are yes ('Yes'), no ('No')")),
    ({"ask": {"Yes": 0.8, "No": 0.3}},
     ("--branch ask: yes:0.8, no:0.3 sum to 1.1, not 1; an exclusive gateway's probabilities "
     "sum to 1 (or leave one flow out: it takes the rest)"),
     ("ask",), ("yes = 0.8, no = 0.3 sum to 1.1, not 1; an exclusive gateway's probabilities "
     "sum to 1 (or leave one flow out: it takes the rest)")),
    ({"check": {"high": 0.5, "low": 0.5}},
     ("--branch check: the conditions of check ('Score high?') decide it; branch probabilities "
     "apply only to a gateway the diagram leaves undecided; drop this --branch, or give the "
     "run inputs its conditions read (--param)"),
     ("check",), ("the conditions of check ('Score high?') decide it; branch probabilities "
     "apply only to a gateway the diagram leaves undecided; leave it out of branches, or give "
     "the run inputs its conditions read (given.params)")),
], ids=["gateway", "flow", "sum", "decided"])
def test_a_refusal_says_where_the_probabilities_were_given(
        package: object, branches: dict[str, dict[str, float]], cli: str,
        at: tuple[str, ...], in_file: str) -> None:
    from opspec.errors import with_hint

    with pytest.raises(BranchRefusal) as raised:
        with_branches(package, branches)     # type: ignore[arg-type]
    assert str(raised.value) == cli              # the command line's words, as before
    with pytest.raises(BranchRefusal) as raised:
        check_branch_table(package, read_branch_table(branches))   # type: ignore[arg-type]
    refusal = raised.value
    assert refusal.at == at
    said = with_hint(refusal.in_file, refusal.file_hint)
    assert said == in_file
    assert "--branch" not in said and "--param" not in said


def test_a_refusal_travels_between_processes() -> None:
    import pickle

    refusal = BranchRefusal("--branch x: no gateway", hint="h", at=("x",), in_file="no gateway")
    assert str(pickle.loads(pickle.dumps(refusal))) == str(refusal)


@pytest.mark.parametrize(("branches", "said"), [
    ({"Pill takn?": {"Yes": 0.8}},
     ("branches['Pill takn?']: no gateway of this id or name (did you mean 'Pill taken?'?); "
      "name a gateway by its id or name, as opspec validate prints them (docs/bpmn.md, "
      "Undecided gateways)")),
    ({"ask": {"Yess": 0.8, "No": 0.2}},
     ("branches['ask']['Yess']: no flow of this id or name out of ask ('Pill taken?') (did "
      "you mean 'Yes'?); its flows are yes ('Yes'), no ('No')")),
    ({"check": {"high": 0.5, "low": 0.5}},
     ("branches['check']: the conditions of check ('Score high?') decide it; branch "
      "probabilities apply only to a gateway the diagram leaves undecided; leave it out of "
      "branches, or give the run inputs its conditions read (params)")),
], ids=["gateway", "flow", "decided"])
def test_the_python_api_is_refused_in_its_own_words(
        tmp_path: Path, branches: dict[str, dict[str, float]], said: str) -> None:
    """``opspec.run(branches={...})`` and ``simulate`` take a dict, not ``--branch`` text: the
    refusal names the dict's keys and no command-line option; ``--branch`` keeps its words
    (the command line passes :class:`CommandLineBranches`)."""
    import opspec
    from opspec.branch_choices import CommandLineBranches, parse_branch_options
    from opspec.errors import with_hint
    from opspec.testing import simulate

    diagram = tmp_path / "pill.bpmn"
    diagram.write_text(DIAGRAM, encoding="utf-8")
    for door in (lambda: opspec.run(diagram, branches=branches, until=60),
                 lambda: simulate(diagram, branches=branches, users=1, days=0.01)):
        with pytest.raises(BranchRefusal) as raised:
            door()
        assert with_hint(raised.value.message, raised.value.hint) == said
    assert isinstance(parse_branch_options(["ask=Yes:1"]), CommandLineBranches)
    with pytest.raises(BranchRefusal) as raised:
        opspec.run(diagram, branches=CommandLineBranches(branches), until=60)
    assert str(raised.value).startswith("--branch ")
