"""A fake PerformerSession (a heap of (time, seq, callback) the test drives) and a small
stand-in for the dispenser's user lane and device, so the user model is tested without the
engine."""

from __future__ import annotations

import heapq
import itertools
import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from opspec.engine.performers import WorkItem
from opspec.engine.trace import EventKind, TraceEvent


class FakeSession:
    """Records every answer; ``run()`` pops callbacks in (time, seq) order."""

    def __init__(self) -> None:
        self.now = 0.0
        self._heap: list[tuple[float, int, Callable[[], None]]] = []
        self._seq = itertools.count()
        self.completed: list[tuple[float, WorkItem, str | None]] = []
        self.omitted: list[tuple[float, WorkItem, str]] = []
        self.traces: list[tuple[float, str, dict[str, Any]]] = []
        self.triggers: list[tuple[float, str]] = []
        self.on_complete: Callable[[WorkItem, str | None], None] | None = None
        self.on_omit: Callable[[WorkItem, str], None] | None = None
        self.events: list[TraceEvent] = []   # what an engine would trace, in order

    def log(self, kind: str, item: WorkItem, **data: Any) -> None:
        self.events.append(TraceEvent(time=self.now, kind=kind, process=item.process,
                                      instance=item.instance, activity=item.activity,
                                      lane="user", participant="user", data=data,
                                      seq=len(self.events)))

    def complete(self, item: WorkItem, data: Mapping[str, Any] | None = None,
                 choice: str | None = None) -> None:
        self.completed.append((self.now, item, choice))
        self.log(EventKind.ACTIVITY_COMPLETED, item, **({"choice": choice} if choice else {}))
        if self.on_complete:
            self.on_complete(item, choice)

    def omit(self, item: WorkItem, reason: str = "") -> None:
        self.omitted.append((self.now, item, reason))
        self.log(EventKind.ACTIVITY_OMITTED, item, reason=reason)
        if self.on_omit:
            self.on_omit(item, reason)

    def fail(self, item: WorkItem, exception: str, message: str = "") -> None:
        raise AssertionError(f"unexpected fail({item.activity}, {exception})")

    def raise_trigger(self, name: str, data: Mapping[str, Any] | None = None) -> None:
        self.triggers.append((self.now, name))

    def call_later(self, delay: float, callback: Callable[[], None]) -> None:
        assert delay >= 0, delay
        heapq.heappush(self._heap, (self.now + delay, next(self._seq), callback))

    def trace(self, kind: str, data: Mapping[str, Any] | None = None) -> None:
        self.traces.append((self.now, kind, dict(data or {})))

    def run(self, until: float = math.inf) -> None:
        while self._heap and self._heap[0][0] <= until:
            time, _, callback = heapq.heappop(self._heap)
            self.now = time
            callback()
        self.now = max(self.now, until) if until < math.inf else self.now


_KEYS = itertools.count(1)


def make_item(activity: str, instance: int = 1, *, choices: tuple[str, ...] = (),
              at: float = 0.0, process: str = "user_workflow") -> WorkItem:
    return WorkItem(key=next(_KEYS), process=process, instance=instance, activity=activity,
                    label=activity, participant="user", lane="user", offered_at=at,
                    choices=choices)


NEXT = {"hear_alarm": "walk_to_dispenser", "walk_to_dispenser": "choose_button",
        "press_wrong_button": "choose_button", "press_report": "take_pill"}


@dataclass
class DispenserLane:
    """The user lane of specs/medication_dispenser.xpdl plus the device's alarm logic
    (alarm, wait 300 s for trg_1, at most 3 alarms), enough to exercise a performer."""

    session: FakeSession
    performer: Any
    deadline: float = 300.0
    max_alarms: int = 3
    instances: itertools.count = field(default_factory=lambda: itertools.count(1))
    offers: list[WorkItem] = field(default_factory=list)
    doses: list[dict[str, Any]] = field(default_factory=list)
    _dose_of: dict[int, dict[str, Any]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.session.on_complete = self._completed
        self.session.on_omit = lambda item, reason: None
        self.performer.attach(self.session)

    def offer(self, activity: str, instance: int, choices: tuple[str, ...] = ()) -> None:
        item = make_item(activity, instance, choices=choices, at=self.session.now)
        self.offers.append(item)
        self.session.log(EventKind.ACTIVITY_OFFERED, item,
                         **({"choices": list(choices)} if choices else {}))
        self.performer.offer(item)

    def dose(self, at: float) -> None:
        """Schedule one dose cycle starting at absolute time ``at``."""
        record: dict[str, Any] = {"first_alarm": at, "alarms": 0, "report": None}
        self.doses.append(record)

        def alarm() -> None:
            if record["report"] is not None:
                return
            if record["alarms"] == self.max_alarms:
                return
            record["alarms"] += 1
            instance = next(self.instances)
            self._dose_of[instance] = record
            self.offer("hear_alarm", instance)
            self.session.call_later(self.deadline, alarm)

        self.session.call_later(at - self.session.now, alarm)

    def _completed(self, item: WorkItem, choice: str | None) -> None:
        record = self._dose_of[item.instance]
        if item.activity == "choose_button":
            nxt = choice
        elif item.activity == "press_report":
            if record["report"] is None and (
                    self.session.now < record["first_alarm"] + self.deadline * self.max_alarms):
                record["report"] = self.session.now
            nxt = NEXT[item.activity]
        else:
            nxt = NEXT.get(item.activity)
        if nxt is None:
            return
        choices = ("press_report", "press_wrong_button") if nxt == "choose_button" else ()
        self.session.call_later(0.0, lambda: self.offer(nxt, item.instance, choices))


def write_trace(path: Path, events: list[TraceEvent]) -> Path:
    """A JSON Lines trace file: the versioned header, then one event per line."""
    lines = [json.dumps({"format": "opspec-trace", "version": 1})]
    lines += [json.dumps(e.to_json()) for e in events]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
