"""A recording PerformerSession and a loop that drains a binding's inbox like the engine."""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from opspec.bindings.inbox import Inbox
from opspec.engine.performers import WorkItem

_keys = itertools.count(1)


def item(application: str, participant: str = "alarm", activity: str | None = None,
         **data: Any) -> WorkItem:
    """A work item as the engine would offer it."""
    return WorkItem(key=next(_keys), process="notify_workflow", instance=1,
                    activity=activity or application, label=application,
                    participant=participant, lane="device", offered_at=0.0,
                    application=application, data=data)


@dataclass
class FakeSession:
    """Records every answer; ``call_later`` runs in simulated time when :meth:`advance` is
    called (the engine's job), so tests see simulated completions deterministically."""

    now: float = 0.0
    completed: list[tuple[WorkItem, Mapping[str, Any] | None]] = field(default_factory=list)
    failed: list[tuple[WorkItem, str, str]] = field(default_factory=list)
    omitted: list[WorkItem] = field(default_factory=list)
    triggers: list[tuple[str, Mapping[str, Any] | None]] = field(default_factory=list)
    traced: list[tuple[str, Mapping[str, Any]]] = field(default_factory=list)
    _timers: list[tuple[float, int, Callable[[], None]]] = field(default_factory=list)
    _seq: itertools.count[int] = field(default_factory=itertools.count)

    def complete(self, item: WorkItem, data: Mapping[str, Any] | None = None,
                 choice: str | None = None) -> None:
        assert item not in self.answered, f"{item.activity} answered twice"
        self.completed.append((item, data))

    def omit(self, item: WorkItem, reason: str = "") -> None:
        self.omitted.append(item)

    def fail(self, item: WorkItem, exception: str, message: str = "") -> None:
        assert item not in self.answered, f"{item.activity} answered twice"
        self.failed.append((item, exception, message))

    def raise_trigger(self, name: str, data: Mapping[str, Any] | None = None) -> None:
        self.triggers.append((name, data))

    def call_later(self, delay: float, callback: Callable[[], None]) -> None:
        heapq.heappush(self._timers, (self.now + delay, next(self._seq), callback))

    def trace(self, kind: str, data: Mapping[str, Any] | None = None) -> None:
        self.traced.append((kind, dict(data or {})))

    # -- helpers for assertions
    @property
    def answered(self) -> list[WorkItem]:
        return [c[0] for c in self.completed] + [f[0] for f in self.failed] + self.omitted

    def kinds(self, kind: str) -> list[Mapping[str, Any]]:
        return [data for k, data in self.traced if k == kind]

    def faults(self) -> list[str]:
        return [data["fault"] for data in self.kinds("fault")]

    def advance(self) -> None:
        """Run every simulated timer (the engine advancing its clock)."""
        while self._timers:
            self.now, _, callback = heapq.heappop(self._timers)
            callback()


def run_until(inbox: Inbox, session: FakeSession, done: Callable[[], bool],
              timeout: float = 10.0) -> None:
    """Drain ``inbox`` on this thread (as the engine does) until ``done()``; fail after
    ``timeout`` wall seconds with what was seen, instead of hanging."""
    import time
    deadline = time.monotonic() + timeout
    while True:
        inbox.drain(session)
        session.advance()
        if done():
            return
        left = deadline - time.monotonic()
        if left <= 0:
            raise AssertionError(f"condition not reached in {timeout} s; traced: "
                                 f"{session.traced}")
        inbox.wait(min(left, 0.5))
