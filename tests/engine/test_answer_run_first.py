"""A performer's answer from outside a drain (a timed callback of its own): ``Offers.
performer_complete`` runs the activity's ``body_done`` itself, as the first item of the drain
that follows (``_body_done_now``), instead of queueing it and draining. The run is the same
as with the item queued: the same trace, and the same step count of the instant after every
answer (the zero-time guard's), whether the answer's body queues more work or not, when work
was queued before it without a drain, when the guard is near its limit, and when the body
raises."""

from __future__ import annotations

from typing import Any

import pytest
from builders import manual, pkg, proc

from opspec.engine.offers import Offers
from opspec.engine.simulation import Simulation
from opspec.engine.timers import TUPLES
from opspec.engine.workitem import WorkItem

from_source = pytest.mark.skipif(not TUPLES, reason="compiled: Offers cannot be patched")


def _queued(self: Offers, ai: Any, data: Any) -> None:
    """The answer's item queued, then drained (what ``performer_complete`` did before)."""
    state = self.state
    state.ready.append((self.activities.body_done_q, ai, data, None))
    state.drain()


class _Answers:
    """Completes every item 3 s after its offer, from a timed callback of its own, noting
    the instant's step count after each answer; ``before``: what it does just before."""

    def __init__(self, before: str) -> None:
        self.before = before
        self.steps: list[tuple[str, float, int]] = []
        self.ran: list[str] = []

    def attach(self, session: Any) -> None:
        self.session = session

    def offer(self, item: WorkItem) -> None:
        self.ran.append(f"offered {item.activity}")
        self.session.call_later(3.0, lambda: self._answer(item))

    def _answer(self, item: WorkItem) -> None:
        sim = self.sim
        if self.before == "queued":         # work queued without a drain runs first
            sim.ready.append((self._note, "queued", None, None))
        elif self.before == "near limit":   # the guard one step from its limit
            sim.instant, sim.instant_steps = sim.now, sim.max_instant_steps - 1
        self.session.complete(item)
        # (the guard's sampler: set where a step past the limit was noted, with what it
        # noted: the steps, and the drains among them)
        sampler = sim.sampler
        self.steps.append((item.activity, sim.now, sim.instant_steps,
                           None if sampler is None else (sampler.steps, sampler.events)))

    def _note(self, name: str, _b: Any, _c: Any) -> None:
        # (with the activities completed so far: the queued work runs before the answer's)
        done = [e.activity for e in self.sim.memory.events if e.kind == "activity.completed"]
        self.ran.append(f"{name} after {','.join(done)}")

    def withdraw(self, item: WorkItem, reason: str) -> None:
        pass


def _run(before: str) -> tuple[Any, ...]:
    # a's end splits: two tokens queued by its body's end
    spec = pkg(proc("p", [manual("a", split="AND"), manual("b"), manual("c")],
                    [("a", "b"), ("a", "c")]))
    user = _Answers(before)
    sim = Simulation(spec, performers={"user": user}, keep_trace=True)
    user.sim = sim  # type: ignore[attr-defined]
    result = sim.run(until=100.0)
    trace = [(e.time, e.kind, e.activity, dict(e.data), e.seq) for e in result.trace]
    return trace, user.steps, user.ran, result.summary


@pytest.mark.parametrize("before", ["nothing", "queued", "near limit"])
def test_an_answer_counts_the_steps_drain_counted(before: str) -> None:
    trace, steps, ran, _summary = _run(before)
    assert [e[2] for e in trace if e[1] == "activity.completed"] == ["a", "b", "c"]
    assert [s[:2] for s in steps] == [("a", 3.0), ("b", 6.0), ("c", 6.0)]
    # drain's own step, a's item, and the two tokens its split queued (at least)
    assert steps[0][2] >= 4
    assert [s[3] is not None for s in steps] == [before == "near limit"] * 3
    if before == "queued":          # before the answer's own item, which offers b and c
        assert ran == ["offered a", "queued after ", "offered b", "offered c",
                       "queued after a", "queued after a,b"]


@from_source
@pytest.mark.parametrize("before", ["nothing", "queued", "near limit"])
def test_an_answer_run_first_is_the_answer_queued(
        before: str, monkeypatch: pytest.MonkeyPatch) -> None:
    run_first = _run(before)
    monkeypatch.setattr(Offers, "_body_done_now", _queued)
    assert run_first == _run(before)


@from_source
def test_a_body_that_raises_leaves_the_count_drain_left(monkeypatch: pytest.MonkeyPatch) -> None:
    seen = []
    for patch in (False, True):
        if patch:
            monkeypatch.setattr(Offers, "_body_done_now", _queued)
        spec = pkg(proc("p", [manual("a"), manual("b")], [("a", "b")]))
        user = _Answers("nothing")
        sim = Simulation(spec, performers={"user": user})
        user.sim = sim  # type: ignore[attr-defined]

        def broken(*_args: Any) -> None:
            raise RuntimeError("body")

        monkeypatch.setattr(sim.activities, "body_done", broken)
        monkeypatch.setattr(sim.activities, "body_done_q", broken)
        with pytest.raises(RuntimeError, match="body"):
            sim.run(until=100.0)
        seen.append((sim.instant_steps, sim.draining, list(sim.ready)))
    assert seen[0] == seen[1]
    assert seen[0][1] is False
