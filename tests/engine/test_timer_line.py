"""While a run has few timed callbacks waiting, compiled, they are kept as a *line* (a list
sorted by ``(time, sequence)``, the earliest last: ``timers.line_push``, ``list.pop``), and as
a binary heap past ``LINE_MAX`` of them until they are fewer than ``LINE_MIN`` again. The
order is the heap's, which is SimPy's: by time, then in the order they were scheduled
(simpy.core.Environment.schedule orders by ``(time, priority, event id)``)."""

from __future__ import annotations

import heapq
import random
from itertools import pairwise
from typing import Any

import pytest
from builders import act, pkg, proc
from test_timer_heap import _Counted

from opspec.engine.simulation import RunResult, Simulation
from opspec.engine.timers import LINE_MAX, LINE_MIN, TUPLES, Timed, line_push
from opspec.model.sisarl import DeclaredDistribution


@pytest.mark.parametrize("seed", range(3))
def test_a_line_gives_its_entries_in_heapqs_order(seed: int) -> None:
    """``line_push`` and ``pop()`` against ``heapq`` over ``(at, seq)``, many ties in time."""
    rng = random.Random(seed)
    line: list[Timed] = []
    reference: list[tuple[float, int, Timed]] = []
    got: list[Timed] = []
    expected: list[Timed] = []
    for seq in range(2000):
        if line and rng.random() < 0.5:
            got.append(line.pop())
            expected.append(heapq.heappop(reference)[2])
            continue
        entry = Timed()
        entry.at = rng.choice([0.0, 0.5, 1.0, 2.5]) + rng.randrange(4)
        entry.seq = seq
        line_push(line, entry)
        heapq.heappush(reference, (entry.at, seq, entry))
        assert [(e.at, e.seq) for e in line] == sorted(((e.at, e.seq) for e in line),
                                                       reverse=True)
    got.extend(reversed(line))
    expected.extend(entry for _at, _seq, entry in sorted(reference))
    assert got == expected


def _crowd() -> Any:
    """Every 6 s, 200 instances start within a second, each waiting an exponential time of
    mean 1 s: the run's waits pile up to about a hundred and drain to none, in turn."""
    times = ",".join(str(k / 200) for k in range(200))
    wait = act("w", duration=DeclaredDistribution(kind="ExponentialDistribution",
                                                  parameters=(("mean", 1.0),)))
    return pkg(proc("crowd", [wait], start=f"timer:{times} every 6"))


def _rows(result: RunResult) -> list[tuple[Any, ...]]:
    assert result.trace is not None
    return [(e.time, e.kind, e.process, e.instance, e.activity) for e in result.trace]


def test_a_run_that_crosses_between_line_and_heap_keeps_simpys_order() -> None:
    """Waits that pile up past ``LINE_MAX`` and drain below ``LINE_MIN``, again and again:
    the same trace as with a SimPy timeout per callback, and the same ``sim_events``."""
    plain = _Counted()
    expected = Simulation(_crowd(), seed=3, keep_trace=True, env=plain).run(until=20.0)
    sim = Simulation(_crowd(), seed=3, keep_trace=True)
    seen: list[tuple[bool, int]] = []

    def watch(_event: Any) -> None:
        seen.append((sim.lined, len(sim.heap)))
    sim.listeners.append(watch)
    sim.full.append((watch, None))
    got = sim.run(until=20.0)
    assert _rows(got) == _rows(expected)
    assert got.summary["sim_events"] == plain.every
    sizes = [size for _lined, size in seen]
    assert max(sizes) > LINE_MAX and min(sizes[len(sizes) // 2:]) < LINE_MIN
    modes = [lined for lined, _size in seen]
    switches = sum(1 for before, after in pairwise(modes) if before != after)
    assert TUPLES or switches >= 4          # compiled: line to heap and back, twice or more
