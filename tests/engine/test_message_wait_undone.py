"""A catch event's wait for a message is undone when the activity stops waiting: caught, or
interrupted by its deadline (the undoing ``Triggers.wait_trigger`` keeps on the activity
instance: from source the table's own ``pop``, compiled a closure). A message sent after an
interrupted wait is not handed to it: it starts the workflow it starts, or it is kept."""

from __future__ import annotations

from builders import act, catch, deadline, pkg, proc

from engine_runs import completed, events
from opspec.engine.compiled import compile_package
from opspec.engine.simulation import Simulation


def _model(send_at: float) -> object:
    return pkg(proc("a", [catch("d", "timer", seconds=send_at), act("send", raises="message:go")],
                    [("d", "send")]),
               proc("b", ["started_by_go"], start="message:go"),
               proc("c", [catch("wait", "message", "go", deadlines=[deadline(5, "late")]),
                          "after", "handle_late"],
                    [("wait", "after"), ("wait", "handle_late", "exception:late")]))


def test_a_caught_message_leaves_no_wait_behind() -> None:
    sim = Simulation(compile_package(_model(send_at=2.0)), keep_trace=True)
    result = sim.run(until=50.0)
    assert completed(result, "c") == ["wait", "after"]
    assert not events(result, "process.started", process="b")
    assert not sim.waiters.get(("message", "go"))


def test_an_interrupted_wait_is_undone_and_a_later_message_goes_elsewhere() -> None:
    sim = Simulation(compile_package(_model(send_at=9.0)), keep_trace=True)
    result = sim.run(until=50.0)
    assert completed(result, "c") == ["handle_late"]
    assert not sim.waiters.get(("message", "go"))
    assert [e.time for e in events(result, "process.started", process="b")] == [9.0]
