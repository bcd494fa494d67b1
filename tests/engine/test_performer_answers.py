"""A performer answers through its session from wherever it runs: inside the engine's own
callbacks (the stochastic user, from ``call_later``) or from a SimPy process of its own that the
engine never scheduled. The session's ``complete`` and ``call_later`` are the engine's own
methods (``opspec.engine.simulation._Session``); an answer from outside must still be stamped
with the time the clock shows then, not the time the engine last read, and must move the token
on at once (the next work item offered at that time)."""

from __future__ import annotations

from typing import Any

import simpy
from builders import manual, pkg, proc

from opspec.engine.simulation import Simulation
from opspec.engine.workitem import WorkItem


class AnswersFromItsOwnProcess:
    """Completes each work item from a SimPy process of its own, ``delay`` seconds after
    the offer (the engine sees no event of its own at that time), and asks, from that same
    process, to be called back ``after`` seconds later to note the clock."""

    def __init__(self, env: simpy.Environment, delay: float, after: float) -> None:
        self.env = env
        self.delay = delay
        self.after = after
        self.offered: list[tuple[str, float]] = []
        self.called_back: list[float] = []

    def attach(self, session: Any) -> None:
        self.session = session

    def offer(self, item: WorkItem) -> None:
        self.offered.append((item.activity, item.offered_at))
        self.env.process(self._answer(item))

    def _answer(self, item: WorkItem) -> Any:
        yield self.env.timeout(self.delay)
        self.session.complete(item)
        self.session.call_later(self.after, lambda: self.called_back.append(self.session.now))

    def withdraw(self, item: WorkItem, reason: str) -> None:
        pass


def test_an_answer_from_the_performers_own_process_is_stamped_with_the_clocks_time() -> None:
    env = simpy.Environment()
    user = AnswersFromItsOwnProcess(env, delay=7.0, after=2.0)
    sim = Simulation(pkg(proc("p", [manual("a"), manual("b")], [("a", "b")])),
                     performers={"user": user}, keep_trace=True, env=env)
    sim.boot()                              # the workflow starts at time 0
    env.run(until=30.0)
    trace = sim.result().trace
    assert trace is not None
    completions = [(e.activity, e.time) for e in trace if e.kind == "activity.completed"]
    assert completions == [("a", 7.0), ("b", 14.0)]
    # the next work item is offered when the answer comes, and each callback asked for
    # from outside the engine's callbacks runs its delay after the answer
    assert user.offered == [("a", 0.0), ("b", 7.0)]
    assert user.called_back == [9.0, 16.0]
