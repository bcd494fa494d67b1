"""The trace: immutable events the engine emits, the listeners that receive them, and sinks.

The trace is the product. The TUI, metrics, exporters and test predicates consume it; none of
them reaches into engine internals. The JSON Lines form is versioned (``TRACE_FORMAT_VERSION``)
and documented in ``docs/trace-format.md``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Final, Protocol

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
    """The kinds of trace events (plain strings, so filters and files stay readable).

    ``Final``: the compiled engine inlines them instead of looking each one up on the class.
    """

    RUN_STARTED: Final = "run.started"
    RUN_ENDED: Final = "run.ended"
    PROCESS_STARTED: Final = "process.started"
    PROCESS_COMPLETED: Final = "process.completed"
    PROCESS_TERMINATED: Final = "process.terminated"
    PROCESS_ABORTED: Final = "process.aborted"
    PROCESS_SUSPENDED: Final = "process.suspended"
    PROCESS_RESUMED: Final = "process.resumed"
    ACTIVITY_STARTED: Final = "activity.started"
    ACTIVITY_OFFERED: Final = "activity.offered"        # manual/external: waiting for its performer
    ACTIVITY_COMPLETED: Final = "activity.completed"
    ACTIVITY_WITHDRAWN: Final = "activity.withdrawn"    # offer cancelled (deadline, other branch won)
    ACTIVITY_OMITTED: Final = "activity.omitted"        # the performer chose not to perform it
    ACTIVITY_FAILED: Final = "activity.failed"          # implementation raised / performer failed
    ACTIVITY_ABORTED: Final = "activity.aborted"
    TRIGGER_RAISED: Final = "trigger.raised"            # message / signal sent
    TRIGGER_KEPT: Final = "trigger.kept"                # message kept: nobody waits for it yet
    TRIGGER_LOST: Final = "trigger.lost"                # message dropped (see docs/trace-format)
    DEADLINE_EXPIRED: Final = "deadline.expired"
    EXCEPTION_RAISED: Final = "exception.raised"
    DATA_CHANGED: Final = "data.changed"
    MODE_CHANGED: Final = "mode.changed"
    FAULT: Final = "fault"                              # device faults, performer faults
    DEADLOCK: Final = "deadlock"
    QUEUED: Final = "activity.queued"                   # pooled model: waiting for a worker
    BRANCH_CHOSEN: Final = "branch.chosen"              # an undecided gateway drew its branch


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


