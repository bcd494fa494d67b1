"""The run's timer heap (opspec/engine/timers.py) orders its entries as ``heapq`` orders
``(time, sequence, entry)`` tuples: by time, then in the order they were scheduled.

SimPy's own rule, which the heap must keep (simpy.core.Environment.schedule): events are
ordered by ``(time, priority, event id)``, so events of one instant are processed in the
order they were scheduled. The heap's entries carry their time and sequence as fields,
compared as numbers; this checks that against the standard library's heap, with many ties
in time (a robot spec's periods meet at every second), pushes and pops interleaved."""

from __future__ import annotations

import heapq
import random
from collections.abc import Callable

import pytest
from builders import manual, pkg, proc

from opspec.engine.builtin_performers import ScriptedUser
from opspec.engine.dedicated import DedicatedProcessor
from opspec.engine.simulation import Simulation
from opspec.engine.timers import LINE_MAX, TUPLES, Timed, heap_pop, heap_push


@pytest.mark.parametrize("seed", range(5))
def test_pops_in_time_then_scheduling_order_as_heapq(seed: int) -> None:
    # a run's state (its Timers) whose clock is never run: only its heap is used here
    run = Simulation(pkg(proc("p", [manual("a")], [])),
                     performers={"user": ScriptedUser([])})
    rng = random.Random(seed)
    reference: list[tuple[float, int, Callable[[], None]]] = []
    popped: list[Callable[[], None]] = []
    expected: list[Callable[[], None]] = []
    sizes: set[tuple[bool, int]] = set()    # compiled: a line while short, else a heap
    for seq in range(3000):
        sizes.add((run.lined, len(run.heap)))
        if run.heap and rng.random() < 0.45:
            popped.append(run.take_first().callback)    # type: ignore[attr-defined]
            expected.append(heapq.heappop(reference)[2])
            continue
        delay = rng.choice([0.0, 0.2, 0.4, 1.0, 10.0]) + rng.choice([0, 1, 2]) * 0.2

        def callback() -> None: ...

        run.timer(delay, callback)
        heapq.heappush(reference, (delay, seq, callback))
    while run.heap:
        popped.append(run.take_first().callback)        # type: ignore[attr-defined]
        expected.append(heapq.heappop(reference)[2])
    assert popped == expected
    assert len({id(c) for c in expected}) == len(expected) > 1500
    assert max(size for _lined, size in sizes) > LINE_MAX
    assert TUPLES or {lined for lined, _size in sizes} == {True, False}


@pytest.mark.parametrize("seed", range(3))
def test_the_heap_functions_order_entries_as_heapq(seed: int) -> None:
    """``heap_push`` and ``heap_pop`` themselves (from source too, where a run's heap holds
    tuples): the order of ``heapq`` over ``(at, seq)``, and the dedicated processor's
    bursts (entries of one time, any order) counted as over floats."""
    rng = random.Random(seed)
    heap: list[Timed] = []
    reference: list[tuple[float, int]] = []
    popped: list[tuple[float, int]] = []
    expected: list[tuple[float, int]] = []
    for seq in range(2000):
        if heap and rng.random() < 0.45:
            entry = heap_pop(heap)
            popped.append((entry.at, entry.seq))
            expected.append(heapq.heappop(reference))
            continue
        entry = Timed()
        entry.at = float(rng.randrange(12)) / 4
        entry.seq = seq
        heap_push(heap, entry)
        heapq.heappush(reference, (entry.at, seq))
    while heap:
        entry = heap_pop(heap)
        popped.append((entry.at, entry.seq))
        expected.append(heapq.heappop(reference))
    assert popped == expected


def test_the_dedicated_processor_counts_overlapping_bursts() -> None:
    dedicated = DedicatedProcessor()
    for now, cost in [(0.0, 1.0), (0.5, 1.0), (0.5, 0.5), (1.0, 2.0), (1.0, 0.25), (3.5, 1.0)]:
        dedicated.burst(now, cost)
    # at 1.0 the first and third have ended (an end at ``now`` is over): 0.5+1.0, 1.0+2.0,
    # 1.0+0.25 under way; at 3.5 all have
    assert dedicated.summary() == {"bursts": 6, "busy_time": 5.75, "max_busy": 3}
