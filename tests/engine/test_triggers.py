"""Start/end triggers, timers, messages (never buffered), signals, rules, periodic workflows."""

from __future__ import annotations

from builders import act, catch, field, pkg, proc, throw
from conftest import completed, events, run

from opspec.engine.builtin_performers import ScriptedUser
from opspec.engine.config import EngineConfig
from opspec.engine.simulation import simulate

DAY = 86_400.0


def test_timer_start_trigger_fires_at_times_of_day_on_every_day() -> None:
    model = pkg(proc("dose", ["ring"], start="timer:28800,79200"))
    result = run(model, until=3 * DAY)
    starts = [e.time for e in events(result, "process.started", process="dose")]
    assert starts == [28800.0, 79200.0, DAY + 28800, DAY + 79200, 2 * DAY + 28800,
                      2 * DAY + 79200]


def test_periodic_workflow_starts_every_period() -> None:
    model = pkg(proc("tick", ["sample"], start="period:10"))
    result = run(model, until=35.0)
    assert [e.time for e in events(result, "process.started")] == [0.0, 10.0, 20.0, 30.0]


def test_period_directive_without_trigger_is_periodic_too() -> None:
    result = run(pkg(proc("tick", ["sample"], period=5.0)), until=12.0)
    assert len(events(result, "process.started")) == 3


def test_timer_resolution_delays_timers_to_the_next_multiple() -> None:
    model = pkg(proc("p", [catch("wait", "timer", seconds=0.33), "after"], [("wait", "after")]))
    result = run(model, config=EngineConfig(timer_resolution=0.25))
    assert events(result, "activity.completed", activity="wait")[0].time == 0.5


def test_message_starts_a_workflow_and_completes_a_waiting_catch_event() -> None:
    model = pkg(proc("a", [catch("d", "timer", seconds=1.0), act("send", raises="message:go")],
                     [("d", "send")]),
                proc("b", ["first"], start="message:go"),
                proc("c", [catch("wait", "message", "go"), "after"], [("wait", "after")]))
    result = run(model)
    assert completed(result, "b") == ["first"]
    assert completed(result, "c") == ["wait", "after"]


def test_messages_are_not_buffered_for_later_listeners() -> None:
    # the report comes at t=5, the listener only starts listening at t=10
    model = pkg(proc("device", [catch("delay", "timer", seconds=10.0),
                                catch("wait", "message", "report"), "got_it"],
                     [("delay", "wait"), ("wait", "got_it")]))
    user = ScriptedUser([("at 5", "raise report")])
    result = run(model, performers={"someone": user}, until=100.0)
    assert "got_it" not in completed(result)
    assert events(result, "trigger.raised")[0].time == 5.0


def test_throw_event_broadcasts_to_every_waiting_instance() -> None:
    model = pkg(proc("w1", [catch("wait", "signal", "alarm")]),
                proc("w2", [catch("wait", "signal", "alarm")]),
                proc("thrower", [catch("d", "timer", seconds=1.0), throw("shout", "alarm",
                                                                         kind="signal")],
                     [("d", "shout")]))
    result = run(model)
    assert completed(result, "w1") == ["wait"] and completed(result, "w2") == ["wait"]


def test_rule_start_trigger_fires_when_package_data_becomes_true() -> None:
    model = pkg(proc("setter", [catch("d", "timer", seconds=3.0),
                                act("raise_level", assign=[("level", "12")])], [("d", "raise_level")]),
                proc("alarm", ["ring"], start="rule:level > 10"),
                data=[field("level", 0)])
    result = run(model)
    assert [e.time for e in events(result, "process.started", process="alarm")] == [3.0]


def test_rule_catch_event_waits_until_its_condition_holds() -> None:
    model = pkg(proc("p", [act("s", split="AND"), catch("until_hot", "rule", rule="t > 30"),
                           "cool", catch("d", "timer", seconds=2.0),
                           act("heat", assign=[("t", "40")])],
                     [("s", "until_hot"), ("s", "d"), ("until_hot", "cool"), ("d", "heat")],
                     data=[field("t", 20)]))
    result = run(model)
    assert events(result, "activity.completed", activity="until_hot")[0].time == 2.0


def test_end_trigger_terminates_running_instances() -> None:
    model = pkg(proc("worker", [catch("forever", "message", "never")],
                     end_trigger="message:stop"),
                proc("boss", [catch("d", "timer", seconds=7.0), act("stop", raises="message:stop")],
                     [("d", "stop")]))
    result = run(model)
    terminated = events(result, "process.terminated", process="worker")
    assert terminated and terminated[0].time == 7.0


def test_simulate_needs_a_horizon_for_periodic_packages() -> None:
    import pytest

    from opspec.errors import ConfigurationError

    with pytest.raises(ConfigurationError, match="periodic start triggers"):
        simulate(pkg(proc("tick", ["a"], start="period:1")))
    result = simulate(pkg(proc("tick", ["a"], start="period:1")), until=2.5)
    assert result.summary["instances"]["started"] == 3
