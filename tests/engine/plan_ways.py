"""What the tests of the generated plans share: run a package with the plans and with the
interpreter alone (``plans.COMPILED`` set as the compiled build sets it), and compare every
trace event, the summary and the metrics of the two runs."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import pytest

from opspec.engine import plans
from opspec.engine.compiled import compile_package
from opspec.engine.lifecycle import RUNNING, SUSPENDED
from opspec.engine.simulation import Simulation
from opspec.model import Package

#: with the generated plans, and with the interpreter alone
WAYS = ("plans", "interpreter")


def use_way(monkeypatch: pytest.MonkeyPatch, way: str) -> None:
    monkeypatch.setattr(plans, "COMPILED", way != "plans")


def count_resumes(sim: Simulation) -> dict[str, int]:
    """Wrap the run's resume plans (``resumes``, called by ``body_done``, and ``dones``,
    queued in its place) so the test sees how often each ran (by activity id)."""
    ran: dict[str, int] = {}
    table: dict[Any, Any] = sim.activities.resumes
    for key, fn in list(table.items()):
        def resumed(activities: Any, ai: Any, fn: Any = fn, aid: str = key.id) -> None:
            ran[aid] = ran.get(aid, 0) + 1
            fn(activities, ai)
        table[key] = resumed
    table = sim.activities.dones
    for key, fn in list(table.items()):
        def done(ai: Any, activities: Any, data: Any, fn: Any = fn, aid: str = key.id) -> None:
            # (counted where it goes on to the resume: body_done's steps let it)
            if ai.state == RUNNING and ai.frame.inst.state != SUSPENDED:
                ran[aid] = ran.get(aid, 0) + 1
            fn(ai, activities, data)
        table[key] = done
    return ran


def resume_plans(sim: Simulation) -> dict[Any, Any]:
    """The run's resume plans of both kinds (none when the interpreter runs alone)."""
    return {**sim.activities.resumes, **sim.activities.dones}


def seen(result: Any) -> tuple[Any, ...]:
    """Everything a run shows: each trace event whole, the summary, the metrics."""
    trace = [(e.time, e.kind, e.process, e.instance, e.activity, e.lane, e.participant,
              e.package, dict(e.data), e.seq) for e in result.trace]
    return trace, result.summary, result.metrics


def run_both(monkeypatch: pytest.MonkeyPatch, package: Package, until: float,
             count: Callable[[Simulation], dict[str, int]],
             table: Callable[[Simulation], Mapping[Any, Any]],
             make_kwargs: Callable[[], dict[str, Any]]) -> tuple[Any, dict[str, int]]:
    """Run ``package`` both ways and assert they agree; the result, and what ``count`` saw
    of the plans run (the interpreter's run has none: ``table`` of it is empty)."""
    results = []
    ran: dict[str, int] = {}
    for way in WAYS:
        use_way(monkeypatch, way)
        sim = Simulation(compile_package(package), keep_trace=True, **make_kwargs())
        if way == "plans":
            ran = count(sim)
        else:
            assert not table(sim)
        results.append(seen(sim.run(until=until)))
    assert results[0] == results[1]
    return results[0], ran
