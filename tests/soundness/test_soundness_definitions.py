"""The three conditions of van der Aalst's soundness, each broken by the smallest XPDL process,
as `opspec check` reports it (at the line of the activity concerned) and as `opspec run`
shows it (docs/soundness.md, What "sound" means here).

A workflow net is sound iff (W.M.P. van der Aalst, "The Application of Petri Nets to Workflow
Management", J. Circuits, Systems and Computers 8(1), 1998):
  (i)   option to complete: from every state reachable from i, the state o can be reached;
  (ii)  proper completion: o is the only reachable state with a token in the sink o;
  (iii) no dead transitions: every transition can fire in some reachable state.
An XPDL process has no single sink: it completes when no token is left."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main

HEAD = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026</Created></PackageHeader>
  <WorkflowProcesses>
    <WorkflowProcess Id="w">
      <ProcessHeader/>
      <DataFields><DataField Id="x"><DataType><BasicType Type="BOOLEAN"/></DataType><InitialValue>{x}</InitialValue></DataField></DataFields>
      <Activities>
"""                                                           # activities from line 9 on
TAIL = """      </Activities>
      <Transitions>
{transitions}      </Transitions>
    </WorkflowProcess>
  </WorkflowProcesses>
</Package>
"""


def _activity(spec: str) -> str:
    """'s' start, 'e…' end, 'X:XOR' / 'A:AND' splits, 'J:AND' / 'M:XOR' joins, else a task."""
    name, _, gate = spec.partition(":")
    if name == "s":
        body = "<Event><StartEvent Trigger=\"None\"/></Event>"
    elif name.startswith("e"):
        body = "<Event><EndEvent Result=\"None\"/></Event>"
    elif gate:
        kind = {"XOR": "Exclusive", "AND": "Parallel"}[gate]
        where = "Join" if name in ("J", "M") else "Split"
        body = f"<Route/><TransitionRestrictions><TransitionRestriction><{where} Type=\"{kind}\"/></TransitionRestriction></TransitionRestrictions>"
    else:
        body = "<Implementation><No/></Implementation>"
    return f'        <Activity Id="{name}">{body}</Activity>\n'


def _write(tmp_path: Path, name: str, activities: list[str], flows: list[str],
           x: str = "true") -> Path:
    transitions = ""
    for n, flow in enumerate(flows):
        arrow, _, condition = flow.partition(" if ")
        source, target = arrow.split("->")
        inner = ("<Condition Type=\"OTHERWISE\"/>" if condition == "otherwise" else
                 f"<Condition Type=\"CONDITION\"><Expression>{condition}</Expression></Condition>"
                 if condition else "")
        transitions += f'        <Transition Id="t{n}" From="{source}" To="{target}">{inner}</Transition>\n'
    path = tmp_path / f"{name}.xpdl"
    path.write_text(HEAD.format(x=x) + "".join(map(_activity, activities))
                    + TAIL.format(transitions=transitions), encoding="utf-8")
    return path


def _check(path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, dict]:
    capsys.readouterr()
    status = main(["check", str(path), "--json"])
    return status, json.loads(capsys.readouterr().out)


def _run(path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, dict]:
    capsys.readouterr()
    status = main(["run", str(path), "--no-user", "--until", "60", "--json"])
    out = capsys.readouterr().out
    return status, (json.loads(out) if out else {})


def test_i_option_to_complete_an_and_join_after_an_xor_split_deadlocks(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, "deadlock", ["s", "X:XOR", "a", "b", "J:AND", "e"],
                  ["s->X", "X->a if x", "X->b if otherwise", "a->J", "b->J", "J->e"])
    status, report = _check(path, capsys)
    assert status == 1 and not report["sound"]
    assert ("deadlock", "J", 13) in {(p["kind"], p["activity"], p["line"])
                                     for p in report["problems"]}
    # the run refuses it for the same reason, at the same line
    assert main(["run", str(path), "--no-user"]) == 1
    assert f"{path}:13: AND-join 'J'" in capsys.readouterr().err


def test_i_option_to_complete_a_loop_without_a_way_out_is_a_livelock(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, "livelock", ["s", "a", "b"], ["s->a", "a->b", "b->a"])
    status, report = _check(path, capsys)
    assert status == 1
    assert [(p["kind"], p["witness"]) for p in report["problems"]] == [
        ("livelock", ["s", "a", "b", "a"])]
    # the run goes round at one instant until the zero-time guard stops it
    assert _run(path, capsys)[0] == 1


def test_i_and_ii_an_end_reached_with_a_token_stuck_is_improper_completion(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, "improper", ["s", "A:AND", "X:XOR", "c", "d", "b", "J:AND", "e",
                                         "e2"],
                  ["s->A", "A->X", "A->b", "X->c if x", "X->d if otherwise", "c->J", "b->J",
                   "d->e2", "J->e"], x="false")
    status, report = _check(path, capsys)
    assert status == 1
    assert [(p["kind"], p["activity"], p["line"]) for p in report["problems"]] == [
        ("improper-completion", "J", 15)]
    # with x false the run takes that path: the instance is left waiting at J
    status, summary = _run(path, capsys)
    assert status == 1 and summary["instances"]["aborted"] == 1
    assert "waiting: J" in summary["deadlocks"][0]


def test_iii_no_dead_transitions_an_island_is_dead(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, "dead", ["s", "e", "y", "z"], ["s->e", "z->y", "y->z"])
    status, report = _check(path, capsys)
    assert status == 1
    assert [(p["kind"], p["activity"], p["line"]) for p in report["problems"]] == [
        ("dead", "y", 11), ("dead", "z", 12)]
    status, summary = _run(path, capsys)
    assert status == 0 and summary["instances"]["completed"] == 1


def test_a_multi_merge_is_sound_here_though_improper_in_a_workflow_net(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, "merge", ["s", "A:AND", "a", "b", "M:XOR", "e"],
                  ["s->A", "A->a", "A->b", "a->M", "b->M", "M->e"])
    status, report = _check(path, capsys)
    assert (status, report["sound"], report["problems"]) == (0, True, [])
    trace = tmp_path / "merge.jsonl"
    assert main(["run", str(path), "--no-user", "--trace", str(trace)]) == 0
    events = [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()[1:]]
    assert sum(e["kind"] == "activity.completed" and e.get("activity") == "e"
               for e in events) == 2
    assert sum(e["kind"] == "process.completed" for e in events) == 1


def test_an_and_split_closed_by_an_and_join_is_sound(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, "sound", ["s", "A:AND", "a", "b", "J:AND", "e"],
                  ["s->A", "A->a", "A->b", "a->J", "b->J", "J->e"])
    status, report = _check(path, capsys)
    assert (status, report["sound"]) == (0, True)
    assert _run(path, capsys)[0] == 0
