"""Start/end triggers, timers, messages (one receiver, kept until caught), signals (broadcast,
never kept), rules, periodic workflows."""

from __future__ import annotations

import dataclasses

from builders import act, catch, deadline, field, pkg, proc, throw
from engine_runs import completed, events, run

from opspec.engine.builtin_performers import ScriptedUser
from opspec.engine.config import EngineConfig

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


def test_a_message_goes_to_one_receiver_a_waiting_catch_event_before_a_start_trigger(
) -> None:
    """BPMN message flow: one sender, one receiver. The activity already waiting for `go`
    catches the first; the second, with nobody waiting, starts workflow b."""
    model = pkg(proc("a", [catch("d", "timer", seconds=1.0), act("send", raises="message:go"),
                           catch("d2", "timer", seconds=1.0),
                           act("send_again", raises="message:go")],
                     [("d", "send"), ("send", "d2"), ("d2", "send_again")]),
                proc("b", ["first"], start="message:go"),
                proc("c", [catch("wait", "message", "go"), "after"], [("wait", "after")]))
    result = run(model)
    assert completed(result, "c") == ["wait", "after"]
    assert [e.time for e in events(result, "activity.completed", process="c",
                                   activity="wait")] == [1.0]
    assert [e.time for e in events(result, "process.started", process="b")] == [2.0]


def test_a_signal_reaches_every_listener_and_starts_every_workflow() -> None:
    model = pkg(proc("a", [catch("d", "timer", seconds=1.0), act("send", raises="signal:go")],
                     [("d", "send")]),
                proc("b", ["first"], start="signal:go"),
                proc("c", [catch("wait", "signal", "go"), "after"], [("wait", "after")]),
                proc("e", [catch("wait", "signal", "go"), "after"], [("wait", "after")]))
    result = run(model)
    assert completed(result, "b") == ["first"]
    assert completed(result, "c") == ["wait", "after"]
    assert completed(result, "e") == ["wait", "after"]


def test_a_message_sent_before_anyone_waits_is_kept_until_caught() -> None:
    # the report comes at t=5, the listener only starts listening at t=10: it catches it then
    model = pkg(proc("device", [catch("delay", "timer", seconds=10.0),
                                catch("wait", "message", "report"), "got_it"],
                     [("delay", "wait"), ("wait", "got_it")]))
    user = ScriptedUser([("at 5", "raise report")])
    result = run(model, performers={"someone": user}, until=100.0)
    assert [e.time for e in events(result, "activity.completed", activity="got_it")] == [10.0]
    assert [e.time for e in events(result, "trigger.kept")] == [5.0]


def test_a_signal_sent_before_anyone_waits_is_not_kept() -> None:
    model = pkg(proc("device", [catch("delay", "timer", seconds=10.0),
                                catch("wait", "signal", "report"), "got_it"],
                     [("delay", "wait"), ("wait", "got_it")]))
    user = ScriptedUser([("at 5", "raise signal:report")])
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


def test_a_periodic_package_runs_one_day_unless_told_otherwise() -> None:
    from opspec.runs import DAY, build

    assert build(pkg(proc("tick", ["a"], start="period:1"))).horizon == DAY
    result = build(pkg(proc("tick", ["a"], start="period:1")), until=2.5).execute()
    assert result.summary["instances"]["started"] == 3


def test_a_reply_goes_to_the_instance_whose_message_started_the_replier() -> None:
    """Device a alarms at t=0, device b at t=1; each alarm starts its own user, and both
    users reply `report` (a's after 10 s, b's after 2 s). b's reply at t=3 goes to b, which
    asked for it, not to a, which has waited longer (correlation by the starting instance)."""
    def device(name: str, at: str) -> object:
        return proc(f"dev_{name}", [act("alarm", raises=f"message:alarm_{name}"),
                                    catch("wait", "message", "report"), "done"],
                    [("alarm", "wait"), ("wait", "done")], start=f"timer:{at}")

    def user(name: str, think: float) -> object:
        return proc(f"user_{name}", [catch("think", "timer", seconds=think),
                                     act("reply", raises="message:report")],
                    [("think", "reply")], start=f"message:alarm_{name}")

    result = run(pkg(device("a", "0"), device("b", "1"), user("a", 10.0), user("b", 2.0)),
                 until=50.0)
    done = {e.process: e.time for e in events(result, "activity.completed", activity="done")}
    assert done == {"dev_a": 10.0, "dev_b": 3.0}


def test_a_reply_to_an_instance_that_has_ended_is_lost_and_says_so() -> None:
    device = proc("device", [act("alarm", raises="message:alarm"),
                             catch("wait", "message", "report",
                                   deadlines=[deadline(2.0, "no_report")]),
                             "done", "gave_up"],
                  [("alarm", "wait"), ("wait", "done"), ("wait", "gave_up", "exception:no_report")])
    user = proc("user", [catch("think", "timer", seconds=5.0),
                         act("reply", raises="message:report")], [("think", "reply")],
                start="message:alarm")
    result = run(pkg(device, user), until=100.0)
    assert "done" not in completed(result, "device")
    [lost] = events(result, "trigger.lost")
    assert lost.time == 5.0 and lost.process == "user"
    assert "has ended" in lost.data["reason"]
    assert events(result, "trigger.kept") == []


def test_a_message_kept_longer_than_message_ttl_is_lost_not_caught() -> None:
    """A press hours before anyone asks is no answer when the spec says so: kept messages
    expire after its opspec:MessageTTL (or the engine option message_ttl), reported as
    trigger.lost. Without either a message waits for its catcher (BPMN: messages are not
    dropped by a default)."""
    model = pkg(proc("device", [catch("delay", "timer", seconds=3600.0),
                                catch("wait", "message", "report"), "got_it"],
                     [("delay", "wait"), ("wait", "got_it")]))
    with_ttl = dataclasses.replace(model, message_ttl=60.0)
    user = ScriptedUser([("at 5", "raise report")])
    result = run(with_ttl, performers={"someone": user}, until=7200.0)
    assert "got_it" not in completed(result)
    [lost] = events(result, "trigger.lost")
    assert lost.time == 3600.0 and "message_ttl 60 s" in lost.data["reason"]
    by_option = run(model, performers={"someone": ScriptedUser([("at 5", "raise report")])},
                    until=7200.0, config=EngineConfig(message_ttl=60.0))
    assert "got_it" not in completed(by_option)
    for kept_forever in (
            run(model, performers={"someone": ScriptedUser([("at 5", "raise report")])},
                until=7200.0),
            run(with_ttl, performers={"someone": ScriptedUser([("at 5", "raise report")])},
                until=7200.0, config=EngineConfig(message_ttl=float("inf")))):
        assert [e.time for e in events(kept_forever, "activity.completed",
                                       activity="got_it")] == [3600.0]
