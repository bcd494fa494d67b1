"""The range finder's reading is rounded to 0.1 mm as Python's ``round(x, 4)`` rounds it,
bit for bit, whether by ``round`` itself or by the compiled shortcut the room takes
(``opspec.worlds.stepping.round4``; a collision's position to 1 mm by ``rounded``), and its
noise is the draw ``Generator.normal`` gives.

Python's documentation of ``round``: "values are rounded to the closest multiple of 10 to
the power minus ndigits; if two multiples are equally close, rounding is done toward the
even choice" -- of the float's exact binary value, so ``round(2.675, 2)`` is 2.67. A trace
must not depend on which path rounded a reading: the same floats compiled or from source,
before and after the shortcut."""

from __future__ import annotations

import math

import numpy as np
import pytest

from opspec.worlds.room import RoomWorld
from opspec.worlds.stepping import round4, rounded


def _values(seed: int, places: int) -> list[float]:
    rng = np.random.default_rng(seed)
    scale = 10.0 ** places
    values = [float(v) for v in rng.uniform(0.0, 6.0, 40_000)]
    values += [float(v) for v in 10.0 ** rng.uniform(-9.0, 5.0, 20_000)]
    # exact and nearly exact halves of the last digit kept: where a shortcut could go wrong
    for k in rng.integers(0, int(6 * scale), 5_000):
        half = (int(k) + 0.5) / scale
        values += [half, math.nextafter(half, 0.0), math.nextafter(half, 1.0)]
    values += [0.0, -0.0, 1e-300, 5 / scale / 10, 1.5 / scale, 2.675, 1e4 - 0.5 / scale, 1e4,
               1e20, math.inf, -1.25 / scale / 10]
    return values


@pytest.mark.parametrize("seed", range(3))
def test_round4_is_round_to_four_places_bit_for_bit(seed: int) -> None:
    for x in _values(seed, 4):
        assert round4(x).hex() == round(x, 4).hex(), x


@pytest.mark.parametrize("seed", range(3))
def test_rounded_is_round_to_three_places_bit_for_bit(seed: int) -> None:
    """``rounded(x, 3, 1000.0)``, as a collision's traced position is rounded."""
    for x in _values(seed, 3):
        assert rounded(x, 3, 1000.0).hex() == round(x, 3).hex(), x
    assert math.isnan(rounded(math.nan, 3, 1000.0))


def test_the_documented_example_of_binary_halves() -> None:
    assert round4(2.675) == round(2.675, 4) == 2.675          # already four places
    assert round4(0.00015) == round(0.00015, 4)              # 0.00015 is below the half
    assert math.isnan(round4(math.nan))


@pytest.mark.parametrize("noise", [0.01, 0.0, 0.3])
def test_the_range_noise_is_the_normal_draw_of_the_worlds_stream(noise: float) -> None:
    """The reading, with its noise, is what ``round(max(0, ray - radius +
    Generator.normal(0, noise)), 4)`` gives, read after read from the same stream."""
    from opspec.worlds.stepping import distance_ahead

    world = RoomWorld(np.random.default_rng(5), range_noise=noise)
    reference = np.random.default_rng(5)
    for n in range(2000):
        robot = world.robot
        robot.heading = n * 0.37
        best = distance_ahead(robot.x, robot.y, robot.heading, world._state.boxes)
        expected = round(max(0.0, best - world.radius + float(reference.normal(0.0, noise))), 4)
        assert world.op_read_range({})["distance"].hex() == expected.hex()


def test_a_negative_range_noise_is_refused_as_numpy_refuses_it() -> None:
    # the world's parameters refuse it before anything runs (a world file's range_noise =
    # -0.1 was an internal error mid-run); a reading with one still refuses it as numpy does
    with pytest.raises(ValueError, match="range_noise must be 0 or more, not -0.1"):
        RoomWorld(np.random.default_rng(5), range_noise=-0.1)
    world = RoomWorld(np.random.default_rng(5))
    world.range_noise = -0.1
    with pytest.raises(ValueError, match="scale"):
        world.op_read_range({})
