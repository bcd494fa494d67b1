"""Per-workflow timing of a run: response times, their percentiles, jitter and deadline misses.

A trace listener for the processor-model questions of the source design: how long does each
instance of a (periodic) workflow take from its start to its completion, how much does that
vary, and how often does it overrun the workflow's declared ``opspec:Deadline``?

- ``response``: completion time − start time of each completed instance; its mean, maximum
  and p50/p90/p99 with distribution-free 95 % intervals (order statistics,
  :func:`opspec.statistics.quantile_interval`; they treat the instances as independent, which
  consecutive instances of a busy system are not quite: read them as optimistic there);
- ``jitter``: max − min response time (the classical response jitter), and its standard
  deviation;
- ``misses``: instances whose deadline expired before they completed (``deadline.expired``
  events of scope ``process``), with the miss rate's exact (Clopper-Pearson) 95 % interval
  over the instances started.

In wall-clock mode (``--realtime``) the times are measured on the wall clock instead
(``clock: "wall"``): each start's lateness against its wall-clock due time (``start_late_*``;
``jitter`` is then max − min start lateness, the release jitter a device would see) and
each response as wall time from start to completion. All times are in seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from opspec.engine import wallclock
from opspec.engine.trace import EventKind as EK
from opspec.engine.trace import TraceEvent

__all__ = ["PERCENTILES", "TimingListener", "WorkflowTiming"]

#: the response-time percentiles reported (as fractions)
PERCENTILES = (0.5, 0.9, 0.99)


@dataclass(slots=True)
class WorkflowTiming:
    started: int = 0
    completed: int = 0
    misses: int = 0
    responses: list[float] = field(default_factory=list)
    start_late: list[float] = field(default_factory=list)      # wall clock only

    def summary(self, clock: str = "simulated") -> dict[str, Any]:
        from opspec.statistics import quantile_interval, rate_interval

        values = sorted(self.responses)
        n = len(values)
        mean = math.fsum(values) / n if n else None
        sd = (math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (n - 1))
              if n > 1 and mean is not None else None)
        out: dict[str, Any] = {
            "clock": clock, "started": self.started, "completed": self.completed,
            "misses": self.misses, "response_mean_s": mean,
            "response_p95_s": values[min(n - 1, int(0.95 * n))] if n else None,
            "response_max_s": values[-1] if n else None,
            "jitter_s": (values[-1] - values[0]) if n else None, "jitter_sd_s": sd}
        for q in PERCENTILES:
            name = f"response_p{round(q * 100)}"
            if n:
                interval = quantile_interval(values, q)
                out[f"{name}_s"] = interval.estimate
                out[f"{name}_ci_s"] = [_finite(interval.lo), _finite(interval.hi)]
            else:
                out[f"{name}_s"] = None
                out[f"{name}_ci_s"] = [None, None]
        rate = rate_interval(min(self.misses, self.started), self.started,
                             method="clopper-pearson")
        out["miss_rate"] = rate.estimate if self.started else None
        out["miss_rate_ci"] = [rate.lo, rate.hi] if self.started else [None, None]
        if clock == "wall" and self.start_late:
            late = sorted(self.start_late)
            m = len(late)
            out.update(start_late_mean_s=math.fsum(late) / m,
                       start_late_p99_s=late[min(m - 1, int(0.99 * m))],
                       start_late_max_s=late[-1], jitter_s=late[-1] - late[0])
        return out


def _finite(value: float) -> float | None:
    """An interval bound the data cannot give (too few instances) is ``None`` in JSON."""
    return value if math.isfinite(value) else None


class TimingListener:
    """Collects :class:`WorkflowTiming` per workflow from the events it selects."""

    selects = frozenset({(EK.PROCESS_STARTED, None, None), (EK.PROCESS_COMPLETED, None, None),
                         (EK.DEADLINE_EXPIRED, None, None)})

    def __init__(self) -> None:
        self.workflows: dict[str, WorkflowTiming] = {}
        self._open: dict[int, float] = {}
        self.clock = "simulated"        # "wall" once an event came in wall-clock mode

    def __call__(self, event: TraceEvent) -> None:
        name = event.process or "?"
        timing = self.workflows.get(name)
        if timing is None:
            timing = self.workflows[name] = WorkflowTiming()
        wall = wallclock.active()
        if wall is not None:
            self.clock = "wall"
        if event.kind == EK.PROCESS_STARTED:
            timing.started += 1
            if wall is not None:
                late = wall.lateness(event.time)
                timing.start_late.append(max(0.0, late))
                start = wall.now()
            else:
                start = event.time
            if event.instance is not None:
                self._open[event.instance] = start
        elif event.kind == EK.PROCESS_COMPLETED:
            timing.completed += 1
            start_at = (self._open.pop(event.instance, None) if event.instance is not None
                        else None)
            if start_at is not None:
                timing.responses.append((wall.now() if wall is not None else event.time)
                                        - start_at)
        elif (event.data or {}).get("scope") == "process":
            timing.misses += 1

    def summary(self) -> dict[str, dict[str, Any]]:
        return {name: t.summary(self.clock) for name, t in sorted(self.workflows.items())}
