"""Messages are durable: a message waits for its catcher; a time to live is only what the
spec says (opspec:MessageTTL), never a silent default that drops a standard file's message."""

from __future__ import annotations

from opspec.engine.triggers import MESSAGE_BUFFER

from .conftest import completed, kinds, run


def test_a_message_waits_for_its_catcher() -> None:
    """BPMN 2.0 §10.4.4 (Intermediate Event types), Message: "A Message arrives from a
    Participant and triggers the Event. This causes the Process to continue if it was waiting
    for the Message" — the message is the sender's, and nothing in BPMN expires it: "sender"
    sends "hello" at t=0, "receiver" waits for it only from t=2 h and catches it then;
    nothing is lost."""
    outcome = run("durable_message.bpmn", until=3 * 3600)
    assert (7200.0, "receive") in completed(outcome, "receiver")
    assert not kinds(outcome, "trigger.lost")
    assert [e.time for e in kinds(outcome, "trigger.kept")] == [0.0]


def test_a_time_to_live_is_an_explicit_directive() -> None:
    """The same file with <opspec:MessageTTL Value="PT60S"/>: the message kept with nobody
    waiting is lost after a minute (trigger.lost names the time to live), so the receiver
    still waits at the end of the run."""
    outcome = run("message_ttl_directive.bpmn", until=3 * 3600)
    assert "receive" not in [name for _t, name in completed(outcome, "receiver")]
    (lost,) = kinds(outcome, "trigger.lost")
    assert lost.time == 7200.0 and "60 s" in lost.data["reason"]


def test_the_buffer_is_bounded_and_says_when_it_overflows() -> None:
    """The buffer of messages kept with nobody waiting is bounded (docs/semantics.md:
    MESSAGE_BUFFER per name and receiver). 101 "hello" messages nobody catches: the first 100
    are kept, the 101st pushes the oldest out, and a trigger.lost says why."""
    outcome = run("message_buffer_overflow.bpmn", until=60)
    assert len(kinds(outcome, "trigger.kept")) == MESSAGE_BUFFER + 1
    (lost,) = kinds(outcome, "trigger.lost")
    assert f"more than {MESSAGE_BUFFER} 'hello' messages were kept" in lost.data["reason"]
    assert "oldest is dropped" in lost.data["reason"]
