"""Issue 33, bounded and located: a workflow that starts itself asynchronously, at once, piles
up an instance per step at one simulated instant (78,000 in 25 s before). The run stops after
a bounded number of instances with a zero-time-cycle error naming the workflow and the
activity that starts it, and ``check`` reports the cycle before any run."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main
from opspec.engine.simulation import Simulation
from opspec.engine.zero_time import MAX_INSTANT_STARTS, SAMPLE_STARTS
from opspec.errors import ZeroTimeCycleError
from opspec.xpdl.loader import load_spec, parse_bytes

SPEC = Path(__file__).with_name("self_start.xpdl")


def test_a_self_starting_workflow_is_stopped_after_a_bounded_number_of_instances() -> None:
    simulation = Simulation(load_spec(SPEC))
    with pytest.raises(ZeroTimeCycleError) as caught:
        simulation.run(until=60)
    message = caught.value.message
    assert "at t=0.000 s" in message
    assert "workflow instances were started at that instant" in message
    assert "process 'p'" in message and "again" in message
    # the bound: the instances started before it stopped (each one holds memory)
    started = simulation.result().summary["instances"]["started"]
    assert MAX_INSTANT_STARTS < started <= MAX_INSTANT_STARTS + SAMPLE_STARTS + 1


def test_many_instances_an_instant_apart_are_no_cycle(monkeypatch: pytest.MonkeyPatch) -> None:
    """The count starts again whenever the clock moves: a workflow that starts itself every
    hour runs for as long as asked."""
    text = SPEC.read_text(encoding="utf-8").replace(
        '<Transition Id="t1" From="again" To="wait"/>',
        '<Transition Id="t1" From="wait" To="again"/>').replace(
        '<Activity Id="again">', '<Activity Id="start_p"><Route/></Activity>'
        '<Activity Id="again">').replace(
        "<Transitions>", '<Transitions><Transition Id="t0" From="start_p" To="wait"/>')
    monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", "2000")   # 120 starts an instant at most
    package = parse_bytes(text.encode(), path=str(SPEC)).package
    assert package is not None
    result = Simulation(package).run(until=200 * 3600)
    assert result.summary["instances"]["started"] > 150


def test_check_reports_the_cycle(capsys: pytest.CaptureFixture[str]) -> None:
    # p starts itself on every run, at once: it can never complete, so it is not sound
    assert main(["check", str(SPEC)]) == 1
    out = capsys.readouterr()
    text = out.out + out.err
    assert "error: p: workflows start each other asynchronously with no delay: p -> p" in text
    assert f"{SPEC}: p: 1 problem(s)" in text
