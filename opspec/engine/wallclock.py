"""Wall-clock mode: step the engine's clock from an asyncio loop.

``simpy.rt.RealtimeEnvironment`` sleeps until its next event, so input arriving meanwhile (a
key press, a serial line) waits for the sleep to end (1.3 s late in issue 3's measurement).
Here an asyncio loop sleeps until the next event is due *or* until :meth:`Simulation.post`
wakes it, whichever comes first; posted callbacks run on the engine's thread, at the simulated
time that corresponds to the wall clock when they *arrived* (``start + (arrival - wall start)
× speed``, capped at ``until``, never backwards): the loop's own latency in noticing a post is
not multiplied by the speed, so a device's answer at 100x is not placed 100 × (that latency)
late. Events already due by then run first, so an answer is never placed before an event that
was due earlier.

Waking on time. asyncio's timers go through ``epoll``, whose timeout is whole milliseconds
rounded up, so an event due in 7.3 ms woken by asyncio alone runs up to ~1 ms late, more when
the machine is busy (p99 2.24 ms idle in issue 21). So the loop sleeps in asyncio only until
``COARSE_S`` before the due time, then waits on the post flag (a ``threading.Event``: a
microsecond timeout, and a post still wakes it) until ``SPIN_S`` before, then busy-waits on
``time.perf_counter`` (checking for posts) for the rest. The fine part blocks the asyncio
loop for at most ``COARSE_S``; the spin costs at most ``SPIN_S`` of CPU per event. The
objects alive when the loop starts are frozen for the garbage collector (``gc.freeze``), so
a full collection during the run only walks what the run created.

Drift (how late events ran relative to their wall-clock due time) is measured for every
event and reported once, in the run summary: ``{"events", "mean_s", "p50_s", "p99_s",
"max_s", "late_10ms", "speed"}``. While a loop runs, :func:`active` gives its
:class:`WallClock`, from which the timing listener reads the wall-clock lateness of each
workflow start (``--timing`` in real time). This is the only module of the engine that reads
the wall clock.
"""

from __future__ import annotations

import asyncio
import contextvars
import gc
import math
import threading
import time
from array import array
from collections import deque
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from opspec.engine.simulation import Simulation

__all__ = ["COARSE_S", "SPIN_S", "WallClock", "active", "run_realtime"]

#: asyncio sleeps end this long before an event's due time (its timers round up to 1 ms)
COARSE_S = 0.002
#: the last stretch before an event's due time is busy-waited (a timed wait ends ~50-100 us
#: late on Linux: its timer slack plus the wake-up)
SPIN_S = 0.0003

_perf = time.perf_counter   # wall-clock


class WallClock:
    """The correspondence between simulated and wall-clock time of a running loop."""

    __slots__ = ("sim_start", "speed", "wall_start")

    def __init__(self, sim_start: float, wall_start: float, speed: float) -> None:
        self.sim_start = sim_start
        self.wall_start = wall_start
        self.speed = speed

    def wall_due(self, sim_time: float) -> float:
        """The ``time.perf_counter`` value at which ``sim_time`` is due."""
        return self.wall_start + (sim_time - self.sim_start) / self.speed

    def sim_at(self, wall: float) -> float:
        """The simulated time that corresponds to the ``time.perf_counter`` value ``wall``."""
        return self.sim_start + (wall - self.wall_start) * self.speed

    def now(self) -> float:
        """The wall clock now (``time.perf_counter``)."""
        return _perf()

    def lateness(self, sim_time: float) -> float:
        """Wall seconds between now and the time ``sim_time`` was due (negative: early)."""
        return _perf() - self.wall_due(sim_time)


# The loop's clock, seen only by the code its own asyncio task runs (the engine's steps and
# the input it drains): a module global was seen by every thread and task of the process, so a
# wall-clock run in one thread (a device test's, a study session's) turned the timing of a
# simulated run in another into wall-clock times, and two loops in one event loop restored
# each other's clock out of turn.
_ACTIVE: contextvars.ContextVar[WallClock | None] = contextvars.ContextVar(
    "opspec_wall_clock", default=None)


def active() -> WallClock | None:
    """The clock of the wall-clock loop this code runs in, if any."""
    return _ACTIVE.get()


def run_realtime(sim: Simulation, until: float | None, speed: float) -> dict[str, Any]:
    """Run ``sim`` against the wall clock (``speed`` simulated seconds per wall second)."""
    return asyncio.run(drive(sim, until, speed))


class _Posts:
    """Input posted from other threads (:meth:`Simulation.post`), and sleeping in the loop
    until some arrives or a time passes, whichever comes first."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self.posted = threading.Event()   # set on the posting thread: callbacks to drain
        self.posted.set()                 # whatever came before the loop took over
        self.arrivals: deque[float] = deque()   # wall time of each post not drained yet
        self.waiter: asyncio.Future[None] | None = None

    def resolve(self) -> None:
        future = self.waiter
        if future is not None and not future.done():
            future.set_result(None)

    def wake(self) -> None:               # on the posting thread
        self.arrivals.append(_perf())
        self.posted.set()
        self.loop.call_soon_threadsafe(self.resolve)

    async def sleep(self, seconds: float | None) -> None:
        """Sleep ``seconds`` (``None``: until a post), or less if something is posted."""
        future: asyncio.Future[None] = self.loop.create_future()
        self.waiter = future
        if self.posted.is_set():          # a post between the check and now: don't sleep
            future.set_result(None)
        handle = None if seconds is None else self.loop.call_later(seconds, self.resolve)
        try:
            await future
        finally:
            self.waiter = None
            if handle is not None:
                handle.cancel()


def _drain_posts(sim: Simulation, posts: _Posts, clock: WallClock,
                 until: float | None) -> bool:
    """Posted callbacks run at the simulated time of the first one's arrival (never
    backwards, never beyond ``until``), after the events due before it: whether they ran
    (``False``: an event is due before the post arrived; step it first, it is overdue)."""
    env = sim.env
    arrivals = posts.arrivals
    target = clock.sim_at(arrivals[0] if arrivals else _perf())
    if until is not None:
        target = min(target, until)
    if env.peek() <= target:
        return False
    if target > env.now:
        env.run(until=target)     # nothing is due before: only moves now
    for _ in range(len(arrivals)):
        arrivals.popleft()
    sim.drain_posts()
    return True


async def drive(sim: Simulation, until: float | None, speed: float) -> dict[str, Any]:
    """The asyncio stepping loop (usable inside an existing loop, e.g. the TUI's)."""
    posts = _Posts(asyncio.get_running_loop())
    posted = posts.posted
    coarse, spin = COARSE_S, SPIN_S    # read once (benchmarks/realtime_drift.py sets 0, 0)
    env = sim.env
    clock = WallClock(env.now, _perf(), speed)
    token = _ACTIVE.set(clock)
    sim.wake = posts.wake
    lateness = array("d")              # one double per event, for the percentiles
    late_max = 0.0
    pending = False                    # posted callbacks wait for the events due before them
    gc.freeze()                        # what exists now is never walked again during the run
    try:
        while True:
            if posted.is_set():
                posted.clear()
                pending = True
            if pending and _drain_posts(sim, posts, clock, until):
                pending = False
                continue
            due = env.peek()
            if until is not None and due > until:
                due = until
            if due == math.inf:
                if not sim.live:
                    break
                await posts.sleep(None)
                continue
            wall_due = clock.wall_due(due)
            delay = wall_due - _perf()
            if delay > coarse:
                await posts.sleep(delay - coarse)
                continue                          # re-check: input may have arrived
            if delay > spin and posted.wait(delay - spin):
                continue                          # input arrived first: handle it now
            while _perf() < wall_due and not posted.is_set():
                pass                              # the last stretch: spin
            if posted.is_set():
                continue
            if until is not None and env.peek() > until:
                if env.now < until:
                    env.run(until=until)
                break
            late = _perf() - wall_due
            env.step()
            late_max = max(late_max, late)
            lateness.append(max(0.0, late))
    finally:
        gc.unfreeze()
        sim.wake = None
        try:
            _ACTIVE.reset(token)
        except ValueError:      # closed from another context (a loop abandoned, collected)
            pass
    return summarise(lateness, late_max, speed)


def summarise(lateness: array[float], late_max: float, speed: float) -> dict[str, Any]:
    """The drift summary of the events' lateness (seconds, 0 for events on time)."""
    values = sorted(lateness)
    n = len(values)

    def quantile(q: float) -> float:
        return values[min(n - 1, int(q * n))] if n else 0.0

    return {"events": n, "mean_s": sum(values) / n if n else 0.0, "p50_s": quantile(0.5),
            "p99_s": quantile(0.99), "max_s": late_max,
            "late_10ms": sum(1 for v in values if v > 0.010), "speed": speed}
