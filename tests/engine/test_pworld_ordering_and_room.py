"""What the pworld pass changed keeps its meaning (docs/engine-performance.md, "pworld"):

- ``field < constant`` compares a float field with the constant as two C doubles where that
  is Python's comparison; every operator, constant and value gives what the tree walker
  gives (its answer or its error), including NaN, signed zeros, infinities, integers past
  2**53, NumPy floats and numbers as text;
- the bumper's answer is a new dictionary at each reading (copied from a fixed one);
- the range noise set on the room is the one its compiled performer reads.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from opspec.engine.conditions import compile_condition, evaluate_condition
from opspec.engine.scope import Scope
from opspec.errors import ExecutionError
from opspec.model.expressions import Binary, Literal, Name
from opspec.worlds.device import devices_of
from opspec.worlds.room import RoomWorld

CONSTANTS: list[Any] = [0.35, 20, -3, 0, 0.0, -0.0, 2 ** 53, 2 ** 53 + 1, -(2 ** 53) - 1,
                        2 ** 60, 1e308, math.inf, -math.inf, 5e-324]
VALUES: list[Any] = [0.34, 0.35, 0.36, 20.0, 19.999999999999996, -3.0, 0.0, -0.0, math.nan,
                     math.inf, -math.inf, 2.0 ** 53, 2.0 ** 53 + 2, 2.0 ** 60, 1e308, 5e-324,
                     20, 2 ** 53 + 1, -(2 ** 53) - 1, np.float64(0.35), np.float64(math.nan),
                     "0.3", "20", "x", True, None]


def _answer(run: Any) -> tuple[str, Any]:
    try:
        return "value", run()
    except ExecutionError as error:
        return "error", error.message


@pytest.mark.parametrize("op", ["<", "<=", ">", ">="])
@pytest.mark.parametrize("constant", CONSTANTS)
def test_an_ordering_with_a_constant_is_the_tree_walkers(op: str, constant: Any) -> None:
    expr = Binary(op, Name(("v",)), Literal(constant))
    held = compile_condition(expr)
    for value in VALUES:
        for data in ({"v": value}, Scope({"v": value}, {}), Scope({}, {"v": value})):
            mine = _answer(lambda: held(data, 1.0))
            walked = _answer(lambda: evaluate_condition(expr, data, clock=lambda: 1.0))
            assert mine == walked, (op, constant, value)
            if mine[0] == "value":
                assert type(mine[1]) is bool


def test_a_missing_field_in_an_ordering_is_named() -> None:
    held = compile_condition(Binary("<", Name(("seen",)), Literal(0.35)))
    with pytest.raises(ExecutionError, match="seen"):
        held(Scope({}, {"other": 1.0}), 2.0)


def test_the_bumper_answers_a_new_dictionary_each_reading() -> None:
    world = RoomWorld(np.random.default_rng(1))
    first = world.op_read_bump({})
    assert first == {"bump": False, "edge": False} and list(first) == ["bump", "edge"]
    first["bump"] = "changed"
    world.bumped = True
    second = world.op_read_bump({})
    assert second == {"bump": True, "edge": False} and second is not first
    second["edge"] = "changed"
    assert world.op_read_bump({}) == {"bump": False, "edge": False}
    world.bumped = True
    assert world.op_read_bump({}) == {"bump": True, "edge": False}


def test_the_range_noise_set_on_the_room_is_the_devices_noise() -> None:
    world = RoomWorld(np.random.default_rng(3), range_noise=0.0)
    assert world.range_noise == 0.0 and world._state.range_noise == 0.0
    world.range_noise = 0.2
    assert world._state.range_noise == 0.2
    devices = devices_of(world)
    devices.announced = True
    got = devices.answer("read_range", {}, 0.0)["distance"]
    world_again = RoomWorld(np.random.default_rng(3), range_noise=0.2)
    assert got == world_again.op_read_range({})["distance"]
