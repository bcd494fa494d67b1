"""A performer's callback with its arguments beside it (the session's ``call_later_with``,
``RunState.call_at_with``) runs as ``call_later(delay, partial(fn, a, b, c))`` would: at the
same time, in the same order among the run's other timed and zero-time work, and the run
counts the same clock events. The stochastic user takes it from source where the session has
it; with a session that lacks it (any other performer session), the partials as before:
both give the same trace, summary and metrics, on the run's own clock and on a shared SimPy
environment (where the entry is a SimPy timeout's callback)."""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Any

import pytest
import simpy
from builders import manual, pkg, proc

from opspec.engine.compiled import compile_package
from opspec.engine.lanes import user_lane
from opspec.engine.random import user_stream
from opspec.engine.simulation import Simulation
from opspec.engine.workitem import WorkItem
from opspec.errors import ZeroTimeCycleError
from opspec.usermodels import performer as performer_module
from opspec.usermodels.loader import load_user_model
from opspec.usermodels.performer import StochasticUser
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]


class _PlainSession:
    """The engine's session without ``call_later_with`` (as another session would be)."""

    def __init__(self, session: Any) -> None:
        self._session = session

    def __getattr__(self, name: str) -> Any:
        if name == "call_later_with":
            raise AttributeError(name)
        return getattr(self._session, name)


class _PlainUser:
    """A stochastic user that sees the session without ``call_later_with`` (a wrapper: the
    compiled user is a native class, which Python cannot subclass)."""

    def __init__(self, user: StochasticUser) -> None:
        self.user = user

    def attach(self, session: Any) -> None:
        self.user.attach(_PlainSession(session))

    def offer(self, item: WorkItem) -> None:
        self.user.offer(item)

    def withdraw(self, item: WorkItem, reason: str) -> None:
        self.user.withdraw(item, reason)


def _dispenser(plain: bool, shared: bool) -> tuple[Any, ...]:
    compiled = compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl"))
    model = load_user_model(ROOT / "specs" / "medication_dispenser.users.toml")
    user = StochasticUser(model, user_stream(3, 0))
    performer: Any = _PlainUser(user) if plain else user
    env = simpy.Environment() if shared else None
    sim = Simulation(compiled, performers={n: performer for n in user_lane(compiled).bind_names},
                     seed=3, scope=(0,), keep_trace=True, env=env)
    result = sim.run(until=6 * 86400.0)
    trace = [(e.time, e.kind, e.process, e.instance, e.activity, dict(e.data), e.seq)
             for e in result.trace]
    return user._call_with is not None, trace, result.summary, result.metrics


@pytest.mark.parametrize("shared", [False, True], ids=["own clock", "shared SimPy"])
def test_the_users_answers_with_their_arguments_run_as_the_partials_did(shared: bool) -> None:
    took, *seen = _dispenser(False, shared)
    plain_took, *plain = _dispenser(True, shared)
    assert not plain_took
    assert took == performer_module._FROM_SOURCE
    assert seen == plain
    trace = seen[0]
    assert sum(1 for e in trace if e[1] == "activity.completed" and e[4] == "take_pill") >= 15
    assert any(e[1] == "user.omitted" for e in trace)       # an alarm not heard, too


class _Orders:
    """Asks for callbacks both ways at once, while the engine drains (the offer) and from
    a timed callback of its own (outside a drain), and notes the order they run in."""

    def __init__(self, with_args: bool) -> None:
        self.with_args = with_args
        self.ran: list[tuple[str, float]] = []

    def attach(self, session: Any) -> None:
        self.session = session

    def _note(self, name: str, _b: Any = None, _c: Any = None) -> None:
        self.ran.append((name, self.session.now))

    def _ask(self, prefix: str, delay: float) -> None:
        session = self.session
        if self.with_args:
            session.call_later_with(delay, self._note, f"{prefix} first", None, None)
        else:
            session.call_later(delay, partial(self._note, f"{prefix} first"))
        session.call_later(delay, partial(self._note, f"{prefix} second"))

    def offer(self, item: WorkItem) -> None:
        self._ask("offer", 0.0)                 # while draining: the ready queue
        self._ask("offer later", 2.0)
        self.session.call_later(5.0, self._outside)
        self.session.call_later(8.0, lambda: self.session.complete(item))

    def _outside(self) -> None:
        self._ask("outside", 0.0)               # not draining: the clock, at this instant

    def withdraw(self, item: WorkItem, reason: str) -> None:
        pass


@pytest.mark.parametrize("shared", [False, True], ids=["own clock", "shared SimPy"])
def test_a_callback_with_arguments_keeps_its_place_at_once_and_later(shared: bool) -> None:
    seen = []
    for with_args in (True, False):
        user = _Orders(with_args)
        sim = Simulation(pkg(proc("p", [manual("a")], [])), performers={"user": user},
                         env=simpy.Environment() if shared else None)
        result = sim.run(until=20.0)
        seen.append((user.ran, result.summary["sim_events"]))
    assert seen[0] == seen[1]
    assert [name for name, _ in seen[0][0]] == [
        "offer first", "offer second", "offer later first", "offer later second",
        "outside first", "outside second"]
    assert [at for _, at in seen[0][0]] == [0.0, 0.0, 2.0, 2.0, 5.0, 5.0]


class _Storm:
    """Asks, from each zero-delay callback, for the next one at the same instant: a storm
    of clock events that queue nothing, which the zero-time guard must stop (each
    callback's drain counts a step, also where it is only counted, nothing being queued)."""

    def __init__(self, with_args: bool) -> None:
        self.with_args = with_args

    def attach(self, session: Any) -> None:
        self.session = session

    def _again(self, _a: Any = None, _b: Any = None, _c: Any = None) -> None:
        if self.with_args:
            self.session.call_later_with(0.0, self._again, None, None, None)
        else:
            self.session.call_later(0.0, self._again)

    def offer(self, item: WorkItem) -> None:
        self.session.call_later(1.0, self._again)

    def withdraw(self, item: WorkItem, reason: str) -> None:
        pass


@pytest.mark.parametrize("with_args", [True, False], ids=["call_later_with", "call_later"])
def test_a_storm_of_callbacks_is_stopped_as_a_zero_time_cycle(
        monkeypatch: pytest.MonkeyPatch, with_args: bool) -> None:
    monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", "2000")
    sim = Simulation(pkg(proc("p", [manual("a")], [])), performers={"user": _Storm(with_args)})
    with pytest.raises(ZeroTimeCycleError):
        sim.run(until=20.0)


class _Queues:
    """A callback that queues zero-time work without draining it (as no performer's answer
    does: the session's calls drain what they queue): its drain runs it at that time."""

    def __init__(self, with_args: bool, sim_of: list[Simulation]) -> None:
        self.with_args = with_args
        self.sim_of = sim_of
        self.ran: list[float] = []

    def attach(self, session: Any) -> None:
        self.session = session

    def _queue(self, _a: Any = None, _b: Any = None, _c: Any = None) -> None:
        sim = self.sim_of[0]
        sim.ready.append((lambda _x, _y, _z: self.ran.append(sim.now), None, None, None))

    def offer(self, item: WorkItem) -> None:
        # (a callback before it at that instant: the instant's count has begun)
        self.session.call_later(3.0, lambda: None)
        if self.with_args:
            self.session.call_later_with(3.0, self._queue, None, None, None)
        else:
            self.session.call_later(3.0, self._queue)
        self.session.call_later(5.0, lambda: self.session.complete(item))

    def withdraw(self, item: WorkItem, reason: str) -> None:
        pass


@pytest.mark.parametrize("with_args", [True, False], ids=["call_later_with", "call_later"])
def test_work_a_callback_queued_runs_at_its_time(with_args: bool) -> None:
    sim_of: list[Simulation] = []
    user = _Queues(with_args, sim_of)
    sim = Simulation(pkg(proc("p", [manual("a")], [])), performers={"user": user})
    sim_of.append(sim)
    sim.run(until=20.0)
    assert user.ran == [3.0]
    assert not sim.ready
