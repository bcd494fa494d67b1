"""The room world's fast stepping (``RoomWorld._advance``) against its one-step-at-a-time
definition (``World._advance`` calling ``RoomWorld._step``): bit for bit the same robot,
contacts, coverage and trace, whatever the commands and the times the devices are used at.

A run's trace must not depend on how the world was stepped: `opspec run` of the robot specs
writes the same trace as before the fast path (checked by hand when it was written, and by
tests/engine/test_native_every_spec.py between the compiled and the source engine). In the
compiled pass the loop (opspec/worlds/stepping.py) runs compiled by mypyc and is compared
here with the interpreted ``_step``: the same floats, compiled or not."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from opspec.worlds import WARD
from opspec.worlds.base import World
from opspec.worlds.room import RoomWorld

COMMANDS = ("forward", "forward", "forward", "back", "stop", "turn_left", "turn_right",
            "turn_random", "charge", "no_such_command")


class _OneStepAtATime(RoomWorld):
    """The reference: every step through ``_step``, as the world was first written (the
    world's state is the same compiled ``RoomState``, read and written through the room's
    properties and the robot's fields, one step at a time)."""

    def advance(self, now: float) -> None:
        World.advance(self, now)

    def _advance(self, now: float) -> None:
        World._advance(self, now)


def _drive(world: RoomWorld, script: list[tuple[float, str, str]]) -> list[Any]:
    """Run ``script`` ((time, operation, command)) on ``world``; everything observable."""
    seen: list[Any] = []
    world.tracer = lambda kind, data: seen.append((kind, dict(data)))
    for at, operation, command in script:
        world.advance(at)
        if operation == "drive":
            seen.append(world.op_drive({"motor_cmd": command}))
        else:
            seen.append(world.operation(operation, {}))
        robot = world.robot
        seen.append((world.time, robot.x, robot.y, robot.heading, robot.command,
                     world.bumped, world.in_contact, world.collisions))
    seen.append(sorted(world.covered))
    return seen


def _script(seed: int, length: int) -> list[tuple[float, str, str]]:
    """Device uses at irregular times (some closer than a step, some many steps apart)."""
    rng = np.random.default_rng(seed)
    t = 0.0
    script = []
    for _ in range(length):
        t += float(rng.choice([0.001, 0.0495, 0.05, 0.2, 0.6, 3.0, 17.0]))
        operation = str(rng.choice(["drive", "drive", "read_range", "read_bump",
                                    "read_battery"]))
        script.append((t, operation, str(rng.choice(COMMANDS))))
    return script


def _bits(value: Any) -> Any:
    """Floats by their bits, so -0.0 and 0.0 (or two nearly equal floats) differ."""
    if isinstance(value, float):
        return value.hex() if not math.isnan(value) else "nan"
    if isinstance(value, dict):
        return {k: _bits(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_bits(v) for v in value]
    return value


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("room", ["vacuum-room", "ward"])
def test_fast_stepping_is_the_step_by_step_world_bit_for_bit(seed: int, room: str) -> None:
    params: dict[str, Any] = dict(WARD) if room == "ward" else {}
    script = _script(seed, 400)
    fast = RoomWorld(np.random.default_rng(seed), **params)
    reference = _OneStepAtATime(np.random.default_rng(seed), **params)
    assert _bits(_drive(fast, script)) == _bits(_drive(reference, script))
    assert fast.collisions > 0 and len(fast.covered) > 20      # the script did get around


def test_a_heading_that_wrapping_still_changes_is_wrapped_at_every_step() -> None:
    """An unwrapped heading (set from outside, 7 rad) is wrapped by the first step, and
    driving straight on uses the wrapped one, as step by step."""
    fast = RoomWorld(np.random.default_rng(1), start=(2.5, 2.0, 0.0), obstacles=())
    reference = _OneStepAtATime(np.random.default_rng(1), start=(2.5, 2.0, 0.0), obstacles=())
    script = [(0.3, "drive", "forward"), (0.9, "read_range", ""), (1.7, "read_bump", "")]
    for world in (fast, reference):
        world.robot.heading = 7.0
    assert _bits(_drive(fast, script)) == _bits(_drive(reference, script))
    assert -math.pi < fast.robot.heading <= math.pi


def test_an_arc_command_takes_the_steps_one_by_one(monkeypatch: pytest.MonkeyPatch) -> None:
    """A command that drives and turns at once (none of the bundled specs has one) is
    stepped by ``_step`` itself."""
    from opspec.worlds import robot

    monkeypatch.setitem(robot.COMMANDS, "arc", (0.3, 0.5))
    fast = RoomWorld(np.random.default_rng(2), obstacles=())
    reference = _OneStepAtATime(np.random.default_rng(2), obstacles=())
    script = [(0.0, "drive", "arc"), (4.0, "read_range", ""), (9.5, "read_bump", "")]
    assert _bits(_drive(fast, script)) == _bits(_drive(reference, script))


def test_the_range_finder_reads_what_ray_to_box_says_bit_for_bit() -> None:
    """``op_read_range`` (one loop over the room and its obstacles) against the geometry's
    ``ray_to_box``: the room's walls from inside, the nearest obstacle face from outside,
    0 from inside an obstacle; from poses all over the room, headings all round."""
    from opspec.worlds.geometry import ray_to_box

    world = RoomWorld(np.random.default_rng(0), range_noise=0.0)
    rng = np.random.default_rng(7)
    for _ in range(3000):
        x, y = float(rng.uniform(0.0, 5.0)), float(rng.uniform(0.0, 4.0))
        heading = float(rng.choice([0.0, math.pi / 2, -math.pi, rng.uniform(-4.0, 4.0)]))
        world.robot.x, world.robot.y, world.robot.heading = x, y, heading
        best = ray_to_box(x, y, heading, world.room, inside=True)
        for box in world.obstacles:
            best = min(best, ray_to_box(x, y, heading, box, inside=False))
        expected = round(max(0.0, best - world.radius + 0.0), 4)
        assert world.op_read_range({})["distance"].hex() == expected.hex(), (x, y, heading)
