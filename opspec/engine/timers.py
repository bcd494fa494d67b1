"""A run's timed callbacks: its own small heap, driven by one SimPy timeout at a time.

Every wait in simulated time of a run (a duration, a deadline, a periodic timer, a worker's
CPU time, a performer's ``call_later``) is a :class:`Timed` entry. On a plain
:class:`simpy.Environment` each entry is a SimPy timeout of its own
(``env.timeout(delay).callbacks.append(entry)``), as before. On a
:class:`~opspec.engine.clock.Clock` the run owns (the one it makes by default), entries go
on a heap ordered by ``(time, sequence)`` in compiled code instead, and one SimPy timeout at
a time, at the heap's earliest time, wakes the run (the *driver*): a SimPy ``Timeout``,
its scheduling and its step are Python code, thousands of instructions each from compiled
code, and most of a run's timers never need one.

The order is SimPy's to the last event. Entries at one instant run in the order they were
scheduled, as SimPy's event ids order them; the clock tells the run about every event
anything else schedules on it (:meth:`Timers.foreign`, from ``Clock.schedule``) *before*
SimPy numbers it, and the run gives its entries due at that event's instant SimPy timeouts
of their own there (they were scheduled first, so they come first), and stops working
through an instant something else now shares. Which entries a driver runs:

* stepping (``env.step()``: the walkthrough, wall-clock runs, a caller's own loop), exactly
  one, so each SimPy step is one timed callback as before;
* inside :meth:`~opspec.engine.simulation.Simulation.run` (``ahead``), every entry due before
  anything else on SimPy's queue (the stop of ``run(until)``, another household's or
  process's event): the run moves on through its own instants without a SimPy event for
  each. SimPy's clock then lags behind the run's; the clock reports the run's time while it
  does (``Clock.now``), and before anything else is scheduled on it, or when the driver
  returns, SimPy's clock is moved to the run's time (``run`` until a timeout at that time),
  so whatever is scheduled next, by anyone, counts from the right time.

Not with a shared processor model (the processors read ``env.now`` themselves): then the
run steps one entry per driver. A lost race (a deadline whose activity completed) costs a
heap entry and a generation check, no SimPy event.

A workflow's own deadline mostly falls due long after its instance ended: it waits beside
the heap (:meth:`Timers.schedule_droppable`) and is dropped, no heap entry at all, where
running it could not be told from not running it (:meth:`Timers._come_due`).

Compiled, the heap is a *line* while it holds few entries (a list sorted the latest first,
:func:`line_push`; the earliest is its last item) and a binary heap past :data:`LINE_MAX`;
from source, :mod:`heapq` over tuples (see ``TUPLES``).
"""

from __future__ import annotations

import math
import types
from collections.abc import Iterator
from heapq import heappop, heappush
from typing import TYPE_CHECKING, Any, Final, final

import simpy

from opspec.engine.clock import Clock
from opspec.engine.zero_time import SAMPLE_STEPS

if TYPE_CHECKING:
    # (a native 64-bit integer compiled; from source only an annotation: no import)
    from mypy_extensions import i64

    from opspec.engine.compiled import CTrigger

__all__ = ["Timed", "Timers", "exact_delay", "heap_pop", "heap_push", "occurrences"]

INF: Final = math.inf
#: The run's entries are kept as a line (:func:`line_push`) up to this many, then as a
#: binary heap until they are fewer than ``LINE_MIN`` again (an insertion into a line moves
#: the entries after its place, a heap's cost grows with the logarithm of its size).
LINE_MAX: Final = 64
LINE_MIN: Final = 16


class Timed:
    """A timed callback of a run: :meth:`go` from the run's heap (the run has set its time),
    ``__call__`` as a SimPy timeout's callback (it reads the time itself).

    On the heap, ``at`` is its time and ``seq`` its place in the order of scheduling (set by
    :meth:`Timers.schedule_timed`; an entry is scheduled once, so they are its own fields:
    no ``(time, sequence, entry)`` tuple per entry, and compared as two native numbers
    instead of by the tuple protocol)."""

    at: float
    seq: i64                    # (machine integers compiled, as Timers.order)
    spare_next: Timed | None    # the next of Timers.spare (set when it is put there)

    def go(self) -> None:
        raise NotImplementedError

    def needed(self) -> bool:
        """Whether :meth:`go` still has anything to do but drain (asked of the entries
        scheduled with :meth:`Timers.schedule_droppable` before they come due)."""
        return True

    def __call__(self, _event: Any) -> None:
        raise NotImplementedError


@final
class _Driver:
    """The SimPy callback that wakes the run (``gen``: which driver; older ones do nothing)."""

    def __init__(self, timers: Timers, gen: int) -> None:
        self.timers = timers
        self.gen = gen

    def __call__(self, _event: Any) -> None:
        self.timers.tick(self.gen)


def exact_delay(base: float, target: float) -> float:
    """The delay SimPy must be given at time ``base`` for an event at exactly ``target``
    (SimPy adds: ``base + (target - base)`` can be an ulp off ``target``)."""
    delay = target - base
    for _ in range(8):
        at = base + delay
        if at == target:
            break
        delay = math.nextafter(delay, INF if at < target else -INF)
    return max(0.0, delay)


#: Whether the engine runs from source (this module is not compiled): then the heap holds
#: ``(at, seq, entry)`` tuples ordered by :mod:`heapq`'s C code, which costs a third of
#: :func:`heap_push`'s and :func:`heap_pop`'s loops interpreted; compiled, those loops compare
#: two native fields per step and beat the tuple protocol (docs/engine-performance.md).
TUPLES: Final = isinstance(exact_delay, types.FunctionType)

class Timers:
    """The clock side of a run's state (:class:`~opspec.engine.runstate.RunState` extends
    it): the time as the run reads it, and its timed callbacks (see the module docstring)."""

    def __init__(self, env: simpy.Environment | None) -> None:
        clock = env if env is not None else Clock()
        self.env: simpy.Environment = clock
        # The time, as the engine reads it: SimPy's ``env.now`` is a Python property, read
        # when a timed callback starts (:meth:`enter`; none at all for the heap's entries)
        # and at each call from outside one (:meth:`sync`), not at every use.
        self.now = float(clock.now)
        self.inside = False         # handling one of its own timed callbacks: now is fresh
        # the entries by (at, seq): compiled, a line (sorted, the earliest last) while it is
        # short, else a binary heap (heap_push, heap_pop); from source heapq's (see TUPLES)
        self.heap: list[Timed] = []
        self.lined = not TUPLES
        # a heap only on a Clock no other run drives (the clock reports the others' events)
        self.heaped = False
        if isinstance(clock, Clock) and clock.owner is None:
            clock.owner = self
            self.heaped = True
        self.order: i64 = 0         # the sequence of the heap's entries
        self.armed_at = INF         # the time of the driver that is valid, if any
        self.driver = 0             # which driver is valid
        self.ticking = False        # a driver is running entries
        self.ahead = False          # inside Simulation.run: may go ahead of SimPy's clock
        self.lagging = False        # SimPy's clock is behind self.now (see Clock.now)
        self.horizon = INF          # the earliest event anything else has on SimPy's queue
        self.shared = False         # something else is due at the instant being run
        self.scheduling = False     # the run is scheduling on the clock itself
        # entries of schedule_droppable not on the heap yet, and the earliest time of them
        self.droppable: list[Timed] = []
        self.droppable_at = INF
        self.moot: list[Timed] = []     # (_come_due's: the entries found not needed)
        # the droppable entries _come_due dropped: nothing holds them any more, so the one
        # who schedules them may use them again (Timed.spare_next chains them)
        self.spare: Timed | None = None

    def sync(self) -> None:
        """Control enters the engine from outside its own timed callbacks (a performer
        answering from a SimPy process or the TUI, ``run``/``step``, a device's post): read
        the clock, which may have moved since the engine last looked."""
        if not self.inside:
            self.now = float(self.env.now)

    def enter(self) -> bool:
        """A timed callback of this run starts as a SimPy timeout's callback: the clock moved
        to its time. Returns whether one was already running (a nested entry leaves the flag
        to the outer one)."""
        self.now = float(self.env.now)
        outer = self.inside
        self.inside = True
        return outer

    def go_now(self, entry: Timed) -> None:
        """``entry`` is due as a SimPy timeout's callback (not from the heap): its ``go``,
        with the time read as :meth:`enter` reads it (the ``__call__`` of a :class:`Timed`
        whose ``go`` needs nothing else)."""
        outer = self.enter()
        try:
            entry.go()
        finally:
            self.inside = outer

    def schedule_timed(self, delay: float, entry: Timed) -> None:
        """``entry`` is due ``delay`` (>= 0) simulated seconds from now."""
        if not self.heaped:
            self.env.timeout(delay).callbacks.append(entry)
            return
        if not self.inside:
            self.now = float(self.env.now)
        at = self.now + delay
        seq = self.order + 1
        self.order = seq
        entry.at = at
        entry.seq = seq
        if TUPLES:      # (_push's case from source in line: a Python frame less an entry)
            rows: list[Any] = self.heap
            heappush(rows, (at, seq, entry))
        else:
            self._push(entry)
        if at < self.armed_at and not self.ticking:
            self.arm()

    def schedule_droppable(self, delay: float, entry: Timed) -> None:
        """:meth:`schedule_timed` for an entry that will most often have nothing to do but
        drain when it comes due (a workflow's deadline, its instance long ended): it waits
        beside the heap, in its place in the order of scheduling, and goes on the heap just
        before the run reaches its time, unless it is no longer :meth:`~Timed.needed` and
        its drain could not be seen (:meth:`_come_due`): then it is dropped, no heap entry,
        pop or drain."""
        if not self.heaped:
            self.env.timeout(delay).callbacks.append(entry)
            return
        if not self.inside:
            self.now = float(self.env.now)
        at = self.now + delay
        self.order += 1
        entry.at = at
        entry.seq = self.order
        self.droppable.append(entry)
        if at < self.droppable_at:
            self.droppable_at = at
            if at < self.armed_at and not self.ticking:
                self.arm()

    def idle(self) -> bool:
        """Whether a drain now would only count a step (nothing queued: see
        :meth:`_come_due`; the run's state says, ``RunState.idle``)."""
        return True

    def _come_due(self, until: float, drop: bool) -> None:
        """The run is about to run what is due at ``until``: the droppable entries due by
        then go on the heap (in their place: each keeps its time and sequence).

        With ``drop`` (the run going through its own instants, :meth:`_run_due`), one that
        is no longer needed is dropped instead where nothing can tell: its drain would only
        count a step of the zero-time guard at its instant (:meth:`idle`), and the next
        thing that runs after it (the heap's earliest entry, the alive ones of these
        included, or the next event on SimPy's queue) is at another instant as the guard
        tells instants apart, so that the count starts again there whether or not the
        drain ran; and fewer of them than the guard samples past its limit (so that the
        count of theirs alone could never stop the run). Stepped, or when something else
        is scheduled on the clock (:meth:`tick`, :meth:`foreign`), they all go on the heap
        and run as any entry: one callback per step, as before."""
        waiting = self.droppable
        moot = self.moot
        later = INF
        kept = 0
        for entry in waiting:
            at = entry.at
            if at > until:
                waiting[kept] = entry
                kept += 1
                if at < later:  # noqa: PLR1730 - min() is a builtin call compiled
                    later = at
            elif drop and not entry.needed():
                moot.append(entry)
            else:
                self._push(entry)
        if kept:
            del waiting[kept:]
        else:
            waiting.clear()
        self.droppable_at = later
        if moot:
            nearest = self.horizon
            if self.heap:
                first = self.first_at()
                if first < nearest:  # noqa: PLR1730
                    nearest = first
            # RunState.drain's test of a new instant, at the next thing to run
            quiet = (len(moot) < SAMPLE_STEPS and self.idle())
            scale = nearest if nearest > 1.0 else 1.0  # noqa: FURB136
            for entry in moot:
                if not (quiet and nearest - entry.at > 1e-9 * scale):
                    self._push(entry)
                else:
                    entry.spare_next = self.spare
                    self.spare = entry
            moot.clear()

    def _push(self, entry: Timed) -> None:
        heap = self.heap
        if TUPLES:
            rows: list[Any] = heap          # the same list, holding tuples (see TUPLES)
            heappush(rows, (entry.at, entry.seq, entry))
        elif self.lined:
            line_push(heap, entry)
            if len(heap) > LINE_MAX:
                heap.reverse()          # the earliest first: sorted, so a binary heap
                self.lined = False
        else:
            heap_push(heap, entry)

    def take_first(self) -> Timed:
        """Take the heap's earliest entry off it (there is one)."""
        heap = self.heap
        if TUPLES:
            rows: list[Any] = heap          # the same list, holding tuples (see TUPLES)
            return heappop(rows)[2]  # type: ignore[no-any-return]
        if self.lined:
            return heap.pop()
        entry = heap_pop(heap)
        if len(heap) < LINE_MIN:
            self._line_up()
        return entry

    def first_at(self) -> float:
        """The time of the heap's earliest entry (there is one)."""
        heap = self.heap
        if TUPLES:
            rows: list[Any] = heap          # the same list, holding tuples (see TUPLES)
            return rows[0][0]  # type: ignore[no-any-return]
        return heap[-1].at if self.lined else heap[0].at

    def arm(self) -> None:
        """Have SimPy wake the run at the heap's earliest time, unless a driver will by then."""
        at = self.first_at() if self.heap else INF
        if self.droppable_at < at:  # noqa: PLR1730
            at = self.droppable_at
        if at >= self.armed_at:             # (INF: nothing to wake the run for)
            return
        self.driver += 1
        self.armed_at = at
        env = self.env
        self.scheduling = True
        try:
            env.timeout(exact_delay(float(env.now), at)).callbacks.append(
                _Driver(self, self.driver))
        finally:
            self.scheduling = False

    def tick(self, gen: int) -> None:
        """The driver ``gen`` is due: run the entries due (one when stepping)."""
        if gen != self.driver:
            return                  # superseded by an earlier driver, or its instant shared
        at = self.armed_at
        self.armed_at = INF
        if self.droppable_at <= at:
            self._come_due(at, False)
        heap = self.heap
        if not heap or self.first_at() != at:
            self.arm()
            return
        ahead = self.ahead
        if ahead:
            self.horizon = float(self.env.peek())
        outer = self.inside
        self.inside = True
        self.ticking = True
        self.shared = False
        try:
            if TUPLES:
                self._run_rows(heap, ahead)
            else:
                self._run_due(heap, ahead)
        finally:
            self.inside = outer
            self.ticking = False
            self.horizon = INF
            if self.lagging:
                self.catch_up()
            self.arm()

    def _run_due(self, heap: list[Timed], ahead: bool) -> None:
        while True:
            # (take_first's line in place: a native call less an entry)
            entry = heap.pop() if self.lined else self.take_first()
            at = entry.at
            self.now = at
            entry.go()
            if not ahead or not heap or self.shared:
                return
            following = heap[-1].at if self.lined else heap[0].at
            if self.droppable_at <= following and (following == at
                                                    or following < self.horizon):
                self._come_due(following, True)     # (what runs next is due by then)
                following = heap[-1].at if self.lined else heap[0].at
            if following != at:
                if not following < self.horizon:
                    return          # something else comes first: SimPy's turn
                self.lagging = True

    def _run_rows(self, rows: list[Any], ahead: bool) -> None:
        """:meth:`_run_due` from source, the heap holding tuples (see ``TUPLES``): a method
        of its own, so that the compiled one tests nothing per entry."""
        while True:
            at, _seq, entry = heappop(rows)
            self.now = at
            entry.go()
            if not ahead or not rows or self.shared:
                return
            following = rows[0][0]
            if self.droppable_at <= following and (following == at
                                                    or following < self.horizon):
                self._come_due(following, True)     # (what runs next is due by then)
                following = rows[0][0]
            if following != at:
                if not following < self.horizon:
                    return          # something else comes first: SimPy's turn
                self.lagging = True

    def _line_up(self) -> None:
        """The heap is short again: a line (see :func:`line_push`)."""
        self.heap.sort(key=_order, reverse=True)
        self.lined = True

    def catch_up(self) -> None:
        """Move SimPy's clock to the run's time (it went ahead: see the module docstring)."""
        self.lagging = False
        env = self.env
        base = float(env.now)
        if self.now > base:
            self.scheduling = True
            try:
                stop = env.timeout(exact_delay(base, self.now))
            finally:
                self.scheduling = False
            env.run(until=stop)     # nothing else is due before it (that is why it lagged)

    def foreign(self, urgent: bool, delay: float) -> None:
        """Something else is being scheduled on the run's clock, ``delay`` from now (the clock
        calls this before SimPy numbers the event)."""
        if self.lagging:
            self.catch_up()
        at = float(self.env.now) + delay
        self.horizon = min(self.horizon, at)
        if self.ticking and at == self.now:
            self.shared = True      # it comes before what this instant schedules from now on
        if urgent:
            return                  # before every timeout of its instant anyway
        if self.droppable_at <= at:
            self._come_due(at, False)
        # entries due at its instant were scheduled before it, so they come first
        if any(_at(entry) == at for entry in self.heap):
            self._give_to_simpy(at)
        if self.armed_at == at:
            self.driver += 1        # what is scheduled at ``at`` from now on comes after it
            self.armed_at = INF
            if not self.ticking:
                self.arm()

    def _give_to_simpy(self, at: float) -> None:
        heap = self.heap
        due = [_entry(item) for item in sorted([item for item in heap if _at(item) == at],
                                               key=_order)]
        # (sorted: a heap, or as a line the latest first)
        heap[:] = sorted([item for item in heap if _at(item) != at], key=_order,
                         reverse=self.lined)
        env = self.env
        delay = exact_delay(float(env.now), at)
        self.scheduling = True
        try:
            for entry in due:
                env.timeout(delay).callbacks.append(entry)
        finally:
            self.scheduling = False


def _at(item: Any) -> float:
    """An item's time, a tuple's (from source) or an entry's."""
    return item[0] if TUPLES else item.at  # type: ignore[no-any-return]


def _entry(item: Any) -> Timed:
    return item[2] if TUPLES else item  # type: ignore[no-any-return]


def _order(item: Any) -> tuple[float, int]:
    if TUPLES:
        return item[0], item[1]
    return item.at, item.seq


def line_push(line: list[Timed], entry: Timed) -> None:
    """Insert ``entry`` into ``line``, a list sorted by ``(at, seq)`` the latest first, in its
    place (found by bisection): the run's entries while they are few. The earliest is then
    taken with ``line.pop()``: compiled, that and an insertion of a few places cost less
    than :func:`heap_pop`'s sifting, which reads and type-checks an entry per comparison
    (docs/engine-performance.md, the deadlines pass)."""
    at = entry.at
    seq = entry.seq
    # (i64: compiled, the bounds are machine integers, no tagged-int arithmetic or checks)
    lo: i64 = 0
    hi: i64 = len(line)
    while lo < hi:
        mid = (lo + hi) >> 1
        other = line[mid]
        other_at = other.at
        if other_at > at or (other_at == at and other.seq > seq):
            lo = mid + 1
        else:
            hi = mid
    line.insert(lo, entry)


def heap_push(heap: list[Timed], entry: Timed) -> None:
    """``heapq.heappush`` by ``(at, seq)``: the same order, compared as native numbers."""
    heap.append(entry)
    at = entry.at
    seq = entry.seq
    pos = len(heap) - 1
    while pos > 0:
        up = (pos - 1) >> 1
        parent = heap[up]
        if at < parent.at or (at == parent.at and seq < parent.seq):
            heap[pos] = parent
            pos = up
        else:
            break
    heap[pos] = entry


def heap_pop(heap: list[Timed]) -> Timed:
    """``heapq.heappop`` by ``(at, seq)``: the earliest entry (the first scheduled of its
    time), taken off the heap (compiled; from source the heap holds tuples for
    :mod:`heapq`, see ``TUPLES``)."""
    last = heap.pop()
    size = len(heap)
    if size == 0:
        return last
    first = heap[0]
    at = last.at
    seq = last.seq
    pos = 0
    child = 1
    # (each entry read from the list costs a type check compiled: read once, its time kept)
    while child < size:
        low = heap[child]
        low_at = low.at
        right = child + 1
        if right < size:
            other = heap[right]
            other_at = other.at
            if other_at < low_at or (other_at == low_at and other.seq < low.seq):
                child = right
                low = other
                low_at = other_at
        if low_at < at or (low_at == at and low.seq < seq):
            heap[pos] = low
            pos = child
            child = child + child + 1
        else:
            break
    heap[pos] = last
    return first


#: seconds in a day: a timer at times of day without a period repeats daily
DAY: Final = 86_400.0


def occurrences(trig: CTrigger, now: float) -> Iterator[float]:
    """Absolute firing times (>= ``now``) of a timer or period trigger."""
    if trig.kind == "period":
        # firings offset, offset + every, ...: ``count`` of them (-1: no end); armed later
        # than some of them (a mode change), the past ones are skipped and still counted
        every = trig.every or 0.0
        if every <= 0:
            yield max(now, trig.offset)
            return
        k = max(0, math.ceil((now - trig.offset) / every))
        while trig.count < 0 or k < trig.count:
            yield trig.offset + k * every
            k += 1
        return
    if not trig.at:
        if trig.every:
            k = 1
            while True:
                yield trig.offset + k * trig.every
                k += 1
        yield now + trig.offset
        return
    every = trig.every or DAY
    cycle = max(0, math.floor((now - trig.offset) / every))
    while True:
        for at in trig.at:
            t = cycle * every + at + trig.offset
            if t >= now:
                yield t
        cycle += 1
