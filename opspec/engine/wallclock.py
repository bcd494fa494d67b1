"""Wall-clock mode: step a plain SimPy environment from an asyncio loop.

``simpy.rt.RealtimeEnvironment`` sleeps until its next event, so input arriving meanwhile (a
key press, a serial line) waits for the sleep to end (1.3 s late in issue 3's measurement).
Here an asyncio loop sleeps until the next event is due *or* until :meth:`Simulation.post`
wakes it, whichever comes first; posted callbacks run on the engine's thread, at the simulated
time that corresponds to the wall clock when they are drained: ``now`` is advanced to
``start + wall elapsed × speed`` first (capped at ``until``, never backwards). Events already
due by then run first, so a device's answer is never placed before an event that was due
earlier, nor (at 1000x) 300 simulated seconds too early because the loop last woke then.

Drift (how late events ran relative to their wall-clock due time) is measured for every
event and reported once, in the run summary: ``{"events", "mean_s", "p99_s", "max_s", "late_10ms"}``.
This is the only module of the engine that reads the wall clock.
"""

from __future__ import annotations

import asyncio
import math
import threading
import time
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from opspec.engine.simulation import Simulation

__all__ = ["run_realtime"]


def run_realtime(sim: Simulation, until: float | None, speed: float) -> dict[str, Any]:
    """Run ``sim`` against the wall clock (``speed`` simulated seconds per wall second)."""
    return asyncio.run(drive(sim, until, speed))


async def drive(sim: Simulation, until: float | None, speed: float) -> dict[str, Any]:
    """The asyncio stepping loop (usable inside an existing loop, e.g. the TUI's)."""
    loop = asyncio.get_running_loop()
    woken = asyncio.Event()
    posted = threading.Event()        # set on the posting thread: callbacks wait to be drained
    posted.set()                      # whatever came before the loop took over

    def wake() -> None:
        posted.set()
        loop.call_soon_threadsafe(woken.set)

    sim.wake = wake
    env = sim.env
    sim_start = env.now
    wall_start = time.perf_counter()  # wall-clock
    late_total = 0.0
    late_max = 0.0
    late_10ms = 0
    count = 0
    lateness_samples: list[float] = []      # for the p99 (a float per event: cheap)
    try:
        while True:
            if posted.is_set():
                posted.clear()
                # the simulated time of "now" on the wall clock (never backwards, never
                # beyond until); callbacks posted from device threads run at that time
                target = sim_start + (time.perf_counter() - wall_start) * speed  # wall-clock
                if until is not None:
                    target = min(target, until)
                if env.peek() > target:
                    if target > env.now:
                        env.run(until=target)     # nothing is due before: only moves now
                    sim.drain_posts()
                    continue
                posted.set()                      # step the overdue events first
            due = env.peek()
            if until is not None and due > until:
                due = until
            if due == math.inf:
                if not sim.live:
                    break
                woken.clear()
                await woken.wait()
                continue
            wall_due = wall_start + (due - sim_start) / speed
            delay = wall_due - time.perf_counter()  # wall-clock
            if delay > 0:
                woken.clear()
                try:
                    await asyncio.wait_for(woken.wait(), timeout=delay)
                    continue                       # input arrived first: handle it now
                except TimeoutError:
                    pass
            if until is not None and env.peek() > until:
                if env.now < until:
                    env.run(until=until)
                break
            lateness = time.perf_counter() - wall_due  # wall-clock
            env.step()
            count += 1
            late_total += max(0.0, lateness)
            late_max = max(late_max, lateness)
            late_10ms += lateness > 0.010
            lateness_samples.append(max(0.0, lateness))
    finally:
        sim.wake = None
    lateness_samples.sort()
    p99 = lateness_samples[min(len(lateness_samples) - 1, int(0.99 * len(lateness_samples)))] \
        if lateness_samples else 0.0
    return {"events": count, "mean_s": late_total / count if count else 0.0,
            "p99_s": p99, "max_s": late_max, "late_10ms": late_10ms, "speed": speed}
