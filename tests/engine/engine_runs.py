"""Run a package with its trace kept, read the trace, and a performer that answers later: what
the engine tests share (a module of its own, not the conftest: every test folder's conftest
is imported as ``conftest``, so a test that imported names from it got another folder's when
both folders were collected together)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from opspec.engine.config import EngineConfig
from opspec.engine.simulation import RunResult, Simulation
from opspec.engine.trace import TraceEvent
from opspec.model import Package


def run(package: Package, *, performers: Mapping[str, Any] | None = None,
        config: EngineConfig | None = None, until: float | None = None, seed: int = 0,
        **kwargs: Any) -> RunResult:
    sim = Simulation(package, config, performers=performers, seed=seed, keep_trace=True,
                     **kwargs)
    return sim.run(until=until)


def events(result: RunResult, kind: str | None = None, process: str | None = None,
           activity: str | None = None) -> list[TraceEvent]:
    assert result.trace is not None
    return [e for e in result.trace
            if (kind is None or e.kind == kind) and (process is None or e.process == process)
            and (activity is None or e.activity == activity)]


def completed(result: RunResult, process: str | None = None) -> list[str]:
    """Ids of completed activities in trace order."""
    return [e.activity for e in events(result, "activity.completed", process)
            if e.activity is not None]


def times(result: RunResult, kind: str, activity: str) -> list[float]:
    return [e.time for e in events(result, kind, activity=activity)]


def kinds(result: RunResult) -> list[str]:
    return [e.kind for e in result.trace or ()]


def before(order: Iterable[str], first: str, second: str) -> bool:
    items = list(order)
    return items.index(first) < items.index(second)


class AnswersLater:
    """A performer that completes every work item it is offered ``delay`` simulated
    seconds later (a token that has to wait for someone)."""

    def __init__(self, delay: float = 5.0) -> None:
        self.delay = delay

    def attach(self, session: Any) -> None:
        self.session = session

    def offer(self, item: Any) -> None:
        self.session.call_later(self.delay, lambda: self.session.complete(item))

    def withdraw(self, item: Any, reason: str) -> None:
        pass
