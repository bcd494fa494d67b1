"""Per-workflow timing of a run: response times, jitter and deadline misses.

A trace listener for the processor-model questions of the source design: how long does each
instance of a (periodic) workflow take from its start to its completion, how much does that
vary, and how often does it overrun the workflow's declared ``opspec:Deadline``?

- ``response``: completion time − start time of each completed instance;
- ``jitter``: max − min response time (the classical response jitter), and its standard
  deviation;
- ``misses``: instances whose deadline expired before they completed (``deadline.expired``
  events of scope ``process``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from opspec.engine.trace import EventKind as EK
from opspec.engine.trace import TraceEvent

__all__ = ["TimingListener", "WorkflowTiming"]


@dataclass(slots=True)
class WorkflowTiming:
    started: int = 0
    completed: int = 0
    misses: int = 0
    responses: list[float] = field(default_factory=list)

    def summary(self) -> dict[str, Any]:
        values = sorted(self.responses)
        n = len(values)
        mean = sum(values) / n if n else None
        sd = (math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1))
              if n > 1 and mean is not None else None)
        return {"started": self.started, "completed": self.completed, "misses": self.misses,
                "response_mean_s": mean,
                "response_p95_s": values[min(n - 1, int(0.95 * n))] if n else None,
                "response_max_s": values[-1] if n else None,
                "jitter_s": (values[-1] - values[0]) if n else None, "jitter_sd_s": sd}


class TimingListener:
    """Collects :class:`WorkflowTiming` per workflow from the events it selects."""

    selects = frozenset({(EK.PROCESS_STARTED, None, None), (EK.PROCESS_COMPLETED, None, None),
                         (EK.DEADLINE_EXPIRED, None, None)})

    def __init__(self) -> None:
        self.workflows: dict[str, WorkflowTiming] = {}
        self._open: dict[int, float] = {}

    def __call__(self, event: TraceEvent) -> None:
        name = event.process or "?"
        timing = self.workflows.get(name)
        if timing is None:
            timing = self.workflows[name] = WorkflowTiming()
        if event.kind == EK.PROCESS_STARTED:
            timing.started += 1
            if event.instance is not None:
                self._open[event.instance] = event.time
        elif event.kind == EK.PROCESS_COMPLETED:
            timing.completed += 1
            start = self._open.pop(event.instance, None) if event.instance is not None else None
            if start is not None:
                timing.responses.append(event.time - start)
        elif (event.data or {}).get("scope") == "process":
            timing.misses += 1

    def summary(self) -> dict[str, dict[str, Any]]:
        return {name: t.summary() for name, t in sorted(self.workflows.items())}
