"""The trace: immutable events the engine emits, the listeners that receive them, and sinks.

The trace is the product. The TUI, metrics, exporters and test predicates consume it; none of
them reaches into engine internals. The JSON Lines form is versioned (``TRACE_FORMAT_VERSION``)
and documented in ``docs/trace-format.md``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

__all__ = [
    "TRACE_FORMAT",
    "TRACE_FORMAT_VERSION",
    "EventKind",
    "TraceEvent",
    "TraceListener",
]

TRACE_FORMAT = "opspec-trace"
TRACE_FORMAT_VERSION = 1


class EventKind:
    """The kinds of trace events (plain strings, so filters and files stay readable)."""

    RUN_STARTED = "run.started"
    RUN_ENDED = "run.ended"
    PROCESS_STARTED = "process.started"
    PROCESS_COMPLETED = "process.completed"
    PROCESS_TERMINATED = "process.terminated"
    PROCESS_ABORTED = "process.aborted"
    PROCESS_SUSPENDED = "process.suspended"
    PROCESS_RESUMED = "process.resumed"
    ACTIVITY_STARTED = "activity.started"
    ACTIVITY_OFFERED = "activity.offered"        # manual/external: waiting for its performer
    ACTIVITY_COMPLETED = "activity.completed"
    ACTIVITY_WITHDRAWN = "activity.withdrawn"    # offer cancelled (deadline, other branch won)
    ACTIVITY_OMITTED = "activity.omitted"        # the performer chose not to perform it
    ACTIVITY_FAILED = "activity.failed"          # implementation raised / performer failed
    ACTIVITY_ABORTED = "activity.aborted"
    TRIGGER_RAISED = "trigger.raised"            # message / signal sent
    DEADLINE_EXPIRED = "deadline.expired"
    EXCEPTION_RAISED = "exception.raised"
    DATA_CHANGED = "data.changed"
    MODE_CHANGED = "mode.changed"
    FAULT = "fault"                              # device faults, performer faults
    DEADLOCK = "deadlock"
    QUEUED = "activity.queued"                   # pooled model: waiting for a worker


@dataclass(frozen=True, slots=True)
class TraceEvent:
    """One thing that happened, at simulated time ``time`` (seconds since the run's epoch).

    ``instance`` is the workflow instance id (unique per run); ``lane`` is ``"device"`` or
    ``"user"`` (or a pool lane id); ``data`` carries data changes and kind-specific details
    (``latency``, ``exception``, ``message``…) and is never mutated after emission.
    """

    time: float
    kind: str
    process: str | None = None
    instance: int | None = None
    activity: str | None = None
    lane: str | None = None
    participant: str | None = None
    package: str | None = None
    data: Mapping[str, Any] = field(default_factory=dict)
    seq: int = 0

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"seq": self.seq, "time": self.time, "kind": self.kind}
        for key in ("process", "instance", "activity", "lane", "participant", "package"):
            value = getattr(self, key)
            if value is not None:
                out[key] = value
        if self.data:
            out["data"] = dict(self.data)
        return out

    @classmethod
    def from_json(cls, obj: Mapping[str, Any]) -> TraceEvent:
        return cls(
            time=float(obj["time"]),
            kind=str(obj["kind"]),
            process=obj.get("process"),
            instance=obj.get("instance"),
            activity=obj.get("activity"),
            lane=obj.get("lane"),
            participant=obj.get("participant"),
            package=obj.get("package"),
            data=dict(obj.get("data") or {}),
            seq=int(obj.get("seq", 0)),
        )


class TraceListener(Protocol):
    """Anything that receives trace events as they happen."""

    def __call__(self, event: TraceEvent) -> None: ...


