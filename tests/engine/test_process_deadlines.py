"""A workflow's deadline (``opspec:Deadline``) fires at its time and in its place among the
run's other timed callbacks, which wait on the run's own timer heap (opspec/engine/timers.py)
instead of as one SimPy timeout each.

What a deadline is (docs/sisarl-xpdl.md): "``opspec:Deadline`` (alias ``opspec:Latency``) |
duration | latency bound of one instance"; and opspec/engine/timing.py counts as misses
"instances whose deadline expired before they completed (``deadline.expired`` events of
scope ``process``)". The engine (opspec/engine/process_deadlines.py) arms it when an
instance starts and emits ``deadline.expired`` if the instance still runs when it falls due.

The reference is the engine on a plain :class:`simpy.Environment`, where every timed callback
is a SimPy timeout of its own: SimPy orders one instant's events in the order they were
scheduled, so two deadlines of one instant fire in the order their instances started."""

from __future__ import annotations

from typing import Any

import simpy
from builders import act, pkg, proc
from test_timer_heap import _Counted

from opspec.engine.simulation import RunResult, Simulation
from opspec.model.sisarl import DeclaredDistribution

# binary fractions: the periods' and deadlines' sums are exact, so the deadlines of the
# three workflows meet at the same instants (k/8 s)
PERIOD = 0.125
SHORT = 0.125           # the deadline of ``fast`` and ``twin``
LONG = 0.25             # the deadline of ``slow``: it falls at a later start's SHORT one


def _work(mean: float) -> Any:
    return act("work", duration=DeclaredDistribution(kind="ExponentialDistribution",
                                                     parameters=(("mean", mean),)))


def _package() -> Any:
    # ``slow`` first: its instance of an instant starts before the others, so its deadline
    # is armed first of the deadlines falling at a later instant
    return pkg(proc("slow", [_work(0.12)], start=f"period:{PERIOD}", deadline=LONG),
               proc("fast", [_work(0.06)], start=f"period:{PERIOD}", deadline=SHORT),
               proc("twin", [_work(0.06)], start=f"period:{PERIOD}", deadline=SHORT))


def _run(env: simpy.Environment | None, until: float = 60.0) -> tuple[Simulation, RunResult]:
    sim = Simulation(_package(), seed=7, keep_trace=True, env=env)
    sim.run(until=until / 3)
    return sim, sim.run(until=until)


def _rows(result: RunResult) -> list[tuple[Any, ...]]:
    assert result.trace is not None
    return [(e.time, e.kind, e.process, e.instance, e.activity, dict(e.data))
            for e in result.trace]


def test_deadlines_fire_as_with_one_simpy_timeout_each() -> None:
    """The same trace, event for event and in the same order, as SimPy gives with a timeout
    per deadline, and the same ``sim_events``."""
    plain = _Counted()
    direct, expected = _run(plain)
    heaped, got = _run(None)
    assert heaped.heaped and not direct.heaped
    assert _rows(got) == _rows(expected)
    assert got.summary["sim_events"] == plain.every


def test_a_deadline_expires_exactly_when_its_instance_overruns_it() -> None:
    """Each instance still running ``deadline`` after its start gets one ``deadline.expired``
    at exactly that time, the others none; deadlines of one instant expire in the order
    their instances started (the slow workflow's, armed a period earlier, first)."""
    _sim, result = _run(None)
    deadline = {"slow": LONG, "fast": SHORT, "twin": SHORT}
    started: dict[int, tuple[str, float]] = {}
    ended: dict[int, float] = {}
    expired: list[tuple[float, str, int]] = []
    for time, kind, process, instance, _activity, data in _rows(result):
        if kind == "process.started":
            started[instance] = (process, time)
        elif kind in ("process.completed", "process.terminated"):
            ended[instance] = time
        elif kind == "deadline.expired":
            assert data == {"deadline": deadline[process], "scope": "process"}
            expired.append((time, process, instance))
    due = sorted((at + deadline[process], instance) for instance, (process, at) in started.items()
                 if at + deadline[process] < 60.0       # (run(until) stops before its instant)
                 and ended.get(instance, float("inf")) > at + deadline[process])
    assert [(time, instance) for time, _p, instance in expired] == due
    missed = {process for _t, process, _i in expired}
    assert missed == {"slow", "fast", "twin"}
    assert 30 < len(expired) < len(started) / 5        # a few overrun among many that do not
    # instants where deadlines of different workflows meet: in the order of their starts
    shared = [[e for e in expired if e[0] == t] for t in sorted({e[0] for e in expired})]
    together = [group for group in shared if len(group) > 1]
    assert together
    for group in together:
        assert [instance for _t, _p, instance in group] == sorted(i for _t, _p, i in group)
    assert any(group[0][1] == "slow" for group in together)
