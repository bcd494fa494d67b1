"""Never a silent hang: the zero-time guard's limit and its diagnosis.

The interpreter counts zero-time steps at the current simulated instant: every item its ready
queue runs, every instantaneous activity its fast path carries a token through, and every
drain (so a storm of zero-delay clock events that queue nothing counts too). The count starts
again whenever the clock moves. On the hot path that is one integer increment and compare per
step; nothing else happens until the count passes :data:`MAX_INSTANT_STEPS`.

Past the limit, each further step is handed to a :class:`ZeroTimeSampler`, which notes the
workflow instance and activity it moves; after :data:`SAMPLE_STEPS` of them (a few
milliseconds) the run stops with a :class:`~opspec.errors.ZeroTimeCycleError` that names the
processes, the activities that keep coming back and the simulated time.

Real specifications take tens to a few thousand steps at one instant (the dispenser: under
100). The limit is 50,000: a workflow that starts itself asynchronously piles up an instance
(and, with the trace kept, its events) per step, and 500,000 steps of that took a minute and
a gigabyte; 50,000 take a few seconds and some 150 MB, and no real run comes near them. ``OPSPEC_MAX_INSTANT_STEPS`` sets
another limit (read when a simulation is created); ``Simulation.max_instant_steps`` sets it
for one simulation.

Workflow instances started at one instant have their own, lower limit,
:data:`MAX_INSTANT_STARTS` (scaled with the step limit): each holds memory until it ends, so a
workflow that starts itself asynchronously is stopped after 3,000 of them (about a second and a
few megabytes) rather than 50,000 steps (20 s and 290 MB uncompiled).
"""

from __future__ import annotations

import os
from typing import Any, Final

from opspec.clock import clock_time
from opspec.errors import SourceLocation, ZeroTimeCycleError

__all__ = ["INSTANT_STEPS_ENV", "MAX_INSTANT_STARTS", "MAX_INSTANT_STEPS", "SAMPLE_STARTS",
           "SAMPLE_STEPS", "ZeroTimeSampler", "max_instant_steps"]

#: Zero-time steps at one simulated instant before a run is stopped as a zero-time cycle.
MAX_INSTANT_STEPS: Final = 50_000
#: The environment variable that overrides :data:`MAX_INSTANT_STEPS` (a positive integer).
INSTANT_STEPS_ENV: Final = "OPSPEC_MAX_INSTANT_STEPS"
#: Steps past the limit watched to name what the cycle runs.
SAMPLE_STEPS: Final = 2_000
#: Workflow instances started at one simulated instant before a run is stopped as a zero-time
#: cycle (issue 33: a workflow that starts itself asynchronously piles up an instance, and its
#: memory, per step; 50,000 of them took 20 s and 290 MB). Real runs start a few at once.
MAX_INSTANT_STARTS: Final = 3_000
#: Instances past that limit watched to name what starts them.
SAMPLE_STARTS: Final = 200

_MAX_PROCESSES = 3
_MAX_ACTIVITIES = 8


def max_instant_steps() -> int:
    """The limit: ``OPSPEC_MAX_INSTANT_STEPS`` when it is a positive integer, else the default."""
    raw = os.environ.get(INSTANT_STEPS_ENV, "")
    try:
        value = int(raw) if raw.strip() else MAX_INSTANT_STEPS
    except ValueError:
        value = MAX_INSTANT_STEPS
    return value if value > 0 else MAX_INSTANT_STEPS


class ZeroTimeSampler:
    """What the steps past the limit move, at the instant ``at``.

    :meth:`record` takes the two first arguments of a ready-queue item (a frame and an
    activity index, an activity instance, ...) or a frame and the activity itself (a
    workflow instance instead of a frame: its one token before it has a frame), or
    ``(None, None)`` for a drain (a clock event at this instant); it returns ``True`` once
    enough steps have been seen for :meth:`error` to name the cycle.
    """

    def __init__(self, at: float, limit: int) -> None:
        self.at = at
        self.limit = limit
        self.steps = 0
        self.events = 0                   # drains: clock events at this instant
        # process id -> activity -> (order key), and the instance ids seen per process
        self.activities: dict[str, dict[str, tuple[int, str]]] = {}
        self.instances: dict[str, set[int]] = {}
        self.hits: dict[str, int] = {}
        # process id -> activity -> where it is written (the error is placed at the cycle)
        self.places: dict[str, dict[str, SourceLocation | None]] = {}

    def record(self, a: Any, b: Any) -> bool:
        self.steps += 1
        if a is None:
            self.events += 1
        else:
            act: Any = None
            inst: Any = None
            graph = getattr(a, "graph", None)
            if graph is not None:                          # a Frame
                inst = a.inst
            elif getattr(a, "frames", None) is not None:
                # a workflow instance whose one token runs without a frame yet
                # (opspec.engine.lone): its top frame's graph and itself
                graph = a.process.graph
                inst = a
            if graph is not None:
                if isinstance(b, int) and 0 <= b < len(graph.activities):
                    act = graph.activities[b]
                elif getattr(b, "process", None) is not None and hasattr(b, "index"):
                    act = b                                # a CompiledActivity
            elif getattr(a, "act", None) is not None:      # an ActivityInstance
                act = a.act
                inst = a.frame.inst
            if act is not None and inst is not None:
                pid: str = inst.process.id
                self.activities.setdefault(pid, {})[act.id] = (act.index, act.id)
                self.places.setdefault(pid, {})[act.id] = act.location
                self.instances.setdefault(pid, set()).add(inst.id)
                self.hits[pid] = self.hits.get(pid, 0) + 1
        return self.steps >= SAMPLE_STEPS

    def place(self) -> SourceLocation | None:
        """Where the cycle is written: the first activity (in the graph's order) of the
        process seen most, as :meth:`describe` names it first; None when no activity moved
        or it was built in Python."""
        if not self.hits:
            return None
        pid = max(self.hits, key=lambda p: self.hits[p])
        first = min(self.activities[pid].values())[1]
        return self.places[pid][first]

    def describe(self) -> str:
        """``process 'p' (instance 1): B, C`` for the processes seen most, or the events."""
        parts = []
        for pid in sorted(self.hits, key=lambda p: -self.hits[p])[:_MAX_PROCESSES]:
            acts = [aid for _key, aid in sorted(self.activities[pid].values())]
            shown = ", ".join(acts[:_MAX_ACTIVITIES]) + (", ..." if len(acts) > _MAX_ACTIVITIES
                                                         else "")
            ids = self.instances[pid]
            if len(ids) == 1:
                which = f"instance {next(iter(ids))}"
            else:
                which = f"{len(ids):,} new instances, {min(ids)} to {max(ids)}"
            parts.append(f"process {pid!r} ({which}): {shown}")
        more = len(self.hits) - _MAX_PROCESSES
        if more > 0:
            parts.append(f"and {more} more process{'es' if more > 1 else ''}")
        if parts:
            return "repeating " + "; ".join(parts)
        return ("repeating SimPy events that move no activity (a performer or binding that "
                "calls back with no delay)")

    def error(self, starts: int = 0) -> ZeroTimeCycleError:
        ran = (f"{starts:,} workflow instances were started at that instant" if starts
               else f"{self.limit:,} steps ran at that instant")
        return ZeroTimeCycleError(
            f"the simulated clock stopped advancing at t={self.at:.3f} s ({clock_time(self.at)}): "
            f"{ran}, {self.describe()}",
            location=self.place(),
            hint="give the cycle a duration, a wait, or a condition that ends it; "
                 f"{INSTANT_STEPS_ENV} raises the limit if this much work at one instant "
                 "is intended",
            sim_time=self.at)
