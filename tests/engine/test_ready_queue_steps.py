"""The zero-time guard's count over the ready queue (``RunState.drain``): each drain and each
item it runs is a step of the instant, across the passes a long burst is cut into (4,096
items, ``_COMPACT``), when an item raises (the items after it stay queued, the count
includes it), and past the limit, where every item is a step of a zero-time cycle until
enough are seen (``SAMPLE_STEPS``): the same count as one step per item, whichever pass of
the burst it falls in."""

from __future__ import annotations

from typing import Any

import pytest
from builders import manual, pkg, proc

from opspec.engine import runstate
from opspec.engine.compiled import compile_package
from opspec.engine.simulation import Simulation
from opspec.engine.zero_time import SAMPLE_STEPS
from opspec.errors import ZeroTimeCycleError

BURST = 9_000                   # over two of drain's passes (_COMPACT items each)


class _Boom(Exception):
    pass


def _sim() -> Simulation:
    sim = Simulation(compile_package(pkg(proc("p", [manual("a")], []))))
    sim.instant = sim.now       # this instant's count goes on (no reset at the drain)
    sim.instant_steps = 0
    return sim


def _burst(sim: Simulation, ran: list[int], raise_at: int = -1) -> None:
    def item(i: Any, _b: Any, _c: Any) -> None:
        if i == raise_at:
            raise _Boom
        ran.append(i)

    sim.ready.extend((item, i, None, None) for i in range(BURST))


def test_a_long_burst_counts_a_step_an_item_across_its_passes() -> None:
    assert runstate._COMPACT * 2 < BURST
    sim = _sim()
    ran: list[int] = []
    _burst(sim, ran)
    sim.drain()
    assert ran == list(range(BURST))
    assert sim.instant_steps == 1 + BURST
    assert sim.ready == [] and not sim.draining


@pytest.mark.parametrize("at", [10, runstate._COMPACT - 1, runstate._COMPACT,
                                runstate._COMPACT + 5])
def test_an_item_that_raises_is_counted_and_the_rest_stay_queued(at: int) -> None:
    sim = _sim()
    ran: list[int] = []
    _burst(sim, ran, raise_at=at)
    with pytest.raises(_Boom):
        sim.drain()
    assert ran == list(range(at))
    assert sim.instant_steps == 1 + at + 1
    assert [item[1] for item in sim.ready] == list(range(at + 1, BURST))
    assert not sim.draining


@pytest.mark.parametrize("limit", [50, runstate._COMPACT - 3, runstate._COMPACT + 2])
def test_past_the_limit_every_item_is_a_step_of_the_cycle(limit: int) -> None:
    sim = _sim()
    sim.max_instant_steps = limit
    ran: list[int] = []
    _burst(sim, ran)
    with pytest.raises(ZeroTimeCycleError):
        sim.drain()
    # item k (from 1) is step k + 1; past the limit each is sampled, the SAMPLE_STEPS-th
    # stops the run before it runs
    assert len(ran) == limit - 2 + SAMPLE_STEPS
    assert ran == list(range(len(ran)))
