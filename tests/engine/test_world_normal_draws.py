"""A world's normal draws taken a batch at a time (``stepping.Normals``, the room's range
noise): the same numbers as the generator's scalar draws, and the generator found by anyone
else (the world's ``rng``) where those handed out leave it, whatever the batch's state."""

from __future__ import annotations

import numpy as np
import pytest

from opspec.worlds.room import RoomWorld
from opspec.worlds.stepping import BATCH


def _scalar(seed: int, normals: int) -> np.random.Generator:
    rng = np.random.default_rng(seed)
    for _ in range(normals):
        rng.standard_normal()
    return rng


def test_the_draws_are_the_generators_own() -> None:
    world = RoomWorld(np.random.default_rng(5))
    draws = world.normal_draws()
    expected = np.random.default_rng(5)
    for _ in range(3 * BATCH + 7):
        assert draws.draw() == float(expected.standard_normal())


@pytest.mark.parametrize("taken", [0, 1, 17, BATCH - 1, BATCH, BATCH + 1, 2 * BATCH + 3])
def test_the_world_rng_is_where_the_draws_leave_it(taken: int) -> None:
    world = RoomWorld(np.random.default_rng(11))
    draws = world.normal_draws()
    got = [draws.draw() for _ in range(taken)]
    expected = np.random.default_rng(11)
    assert got == [float(expected.standard_normal()) for _ in range(taken)]
    # another user of the stream (the random turn's uniform, the Python range reading)
    assert world.rng.uniform(0.0, 1.0) == expected.uniform(0.0, 1.0)
    reading = world.op_read_range({})
    assert reading == {"distance": world._state.read_range(
        0.0 + world.range_noise * float(expected.standard_normal()))}
    # and the batch goes on from there
    assert draws.draw() == float(expected.standard_normal())
    assert world.rng.integers(1 << 30) == expected.integers(1 << 30)


def test_a_new_rng_leaves_the_old_one_where_the_draws_left_it() -> None:
    first = np.random.default_rng(2)
    world = RoomWorld(first)
    draws = world.normal_draws()
    draws.draw()
    draws.draw()
    world.rng = np.random.default_rng(3)
    assert first.standard_normal() == _scalar(2, 2).standard_normal()
    assert draws.draw() == np.random.default_rng(3).standard_normal()
