"""`opspec check` plays the instances `run` makes: at the top level of a process with start
events that have a trigger, each triggered start event starts an instance of its own that runs
only its path (BPMN 2.0 §10.4.2: "Each Start Event is an independent Event. That is, a Process
instance SHALL be generated when the Start Event is triggered."), so the check explores one
token game per kind of instance instead of one with every start node marked together."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import opspec
from opspec.cli import main
from opspec.model.graph import levels
from opspec.model.instance_starts import instance_starts
from opspec.xpdl.loader import load_package

DATA = Path(__file__).resolve().parents[1] / "standard_constructs" / "data"


def _check(path: Path, capsys: pytest.CaptureFixture[str]) -> dict:
    main(["check", "--json", str(path)])
    return json.loads(capsys.readouterr().out.splitlines()[-1])


def test_two_timer_paths_that_meet_at_an_and_join_deadlock_in_check_as_in_run(
        capsys: pytest.CaptureFixture[str]) -> None:
    """Each timer's instance brings one token to the parallel join, never two: `run`
    deadlocks at "both"; `check` said "sound" (it marked both start events in one instance)
    and now reports the deadlock, with the start event of the instance as its witness."""
    path = DATA / "timer_paths_meet_at_and_join.bpmn"
    outcome = opspec.run(path, until=8000, seed=0)
    assert (outcome.problem or "").startswith("deadlock")
    doc = _check(path, capsys)
    deadlock = next(p for p in doc["problems"] if p["kind"] == "deadlock")
    assert deadlock["activity"] == "both"
    assert deadlock["witness"] in (["morning"], ["evening"])
    assert doc["sound"] is False


def test_the_start_sets_follow_the_engine() -> None:
    """One set per triggered start event; the others (a none start event, a node without
    incoming flow) form the set of the instance started without a trigger, made when a none
    start event is among them or when the process is called."""
    package = load_package(DATA / "none_beside_message_start.bpmn").package
    assert package is not None
    process = package.process("p")
    graph = dict(levels(process))[None]
    assert instance_starts(process, graph, called=False) == (("on_call",), ("begin",))
    package = load_package(DATA / "unstarted_beside_timer.bpmn").package
    assert package is not None
    process = package.process("p")
    graph = dict(levels(process))[None]
    assert instance_starts(process, graph, called=False) == (("every_hour",),)
    assert instance_starts(process, graph, called=True) == (("every_hour",), ("report",))
