"""The inclusive (OR) join fires once per activation, consuming one token from each incoming
sequence flow that has one (BPMN 2.0 Table 13.3), also when tasks or another join feed it."""

from __future__ import annotations

from .conftest import completed, kinds, run


def _join_firings(name: str) -> list[float]:
    outcome = run(name, until=60)
    assert [e.kind for e in outcome.trace if e.kind.startswith("process.")] == [
        "process.started", "process.completed"]
    firings = [t for t, activity in completed(outcome) if activity == "join"]
    assert firings == [t for t, activity in completed(outcome) if activity == "after"]
    return firings


def test_two_tokens_on_one_flow_are_two_activations() -> None:
    """BPMN 2.0 Table 13.3 (Inclusive Gateway): "Upon execution, a token is consumed from
    each incoming Sequence Flow that has a token."

    Tasks t1 (1 s) and t2 (2 s) each send a token through "merge" onto flow a; t3 (3 s) one
    onto flow b. At t=3 the join consumes one token of a and the one of b; the second token of
    a is a second activation at once (nothing else can reach flow b). Read as "wait for all
    upstream work, then fire once", the join would swallow the second token of a."""
    assert _join_firings("or_join_two_tokens_on_one_flow.bpmn") == [3.0, 3.0]


def test_a_token_that_can_also_reach_a_flow_with_a_token_does_not_hold_the_join() -> None:
    """BPMN 2.0 Table 13.3: "The Inclusive Gateway is activated if • At least one incoming
    Sequence Flow has at least one token and • For every directed path formed by sequence flow
    that starts with a Sequence Flow f of the diagram that has a token, ends with an incoming
    Sequence Flow of the inclusive gateway that has no token, and does not visit the Inclusive
    Gateway, • There is also a directed path formed by Sequence Flow that starts with f, ends
    with an incoming Sequence Flow of the inclusive gateway that has a token, and does not
    visit the Inclusive Gateway."

    "slow" (5 s) can reach flow b, which has no
    token, but also flow a, which has the token "quick" put there at t=1: the join fires at
    t=1. "slow" then sends its token onto a (x > 0, not x > 5): a second activation at t=5."""
    assert _join_firings("or_join_token_reaching_both.bpmn") == [1.0, 5.0]


def test_a_token_waiting_in_a_parallel_join_upstream_holds_the_join() -> None:
    """BPMN 2.0 Table 13.3 (as above: a token whose only paths end at incoming flows without
    a token holds the join). The token b1 leaves at t=2 waits in the parallel join "both", from where
    the only path leads to flow b, which has no token: the inclusive join waits for "both"
    (t=4) and fires once, with the token of a and the one of b (WCP-7, Structured
    Synchronizing Merge: "the thread of control is passed to the subsequent branch when each
    active incoming branch has been enabled")."""
    assert _join_firings("or_join_fed_by_a_join.bpmn") == [4.0]


def test_nothing_left_over() -> None:
    """Every token the join consumed is accounted for: the instance completes (no token
    parked at the join, no deadlock)."""
    for name in ("or_join_two_tokens_on_one_flow.bpmn", "or_join_token_reaching_both.bpmn",
                 "or_join_fed_by_a_join.bpmn"):
        outcome = run(name, until=60)
        assert not kinds(outcome, "deadlock")
        assert len(kinds(outcome, "process.completed")) == 1
