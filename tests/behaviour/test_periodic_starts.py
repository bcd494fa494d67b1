"""Periodic workflows start at their period's times, and the room's devices read as the room.

The engine counts a period's firings itself (``opspec/engine/triggers.py``, ``_Timer``) and the
room's devices draw the range finder's noise in compiled code (``opspec/worlds/room_devices.py``);
these tests hold both to what a designer reads in the spec and to the room's own definition.
"""

from __future__ import annotations

import math
import random
from pathlib import Path

import numpy as np
from spec_text import assign, compiled, field, process

from opspec.engine.simulation import Simulation
from opspec.engine.workitem import WorkItem
from opspec.worlds.room import RoomWorld
from opspec.worlds.room_devices import RoomDevices
from opspec.worlds.stepping import cover


def _starts(tmp_path: Path, until: float, **directives: str) -> list[float]:
    model = compiled(tmp_path, [process("tick", [assign("a", ("n", "n + 1"))],
                                        fields=[field("n", "INTEGER", "0")], **directives)])
    result = Simulation(model, keep_trace=True).run(until=until)
    assert result.trace is not None
    return [e.time for e in result.trace if e.kind == "process.started"]


def test_a_5_hz_workflow_starts_at_k_times_its_period_without_drift(tmp_path: Path) -> None:
    """opspec:Rate 5Hz: "the workflow starts every 1/5 s" (docs/sisarl-xpdl.md): an hour has
    18,000 starts, the k-th at k * 0.2 s exactly (times are not summed period after period,
    which would drift by an ulp or more per start)."""
    starts = _starts(tmp_path, 3600.0, Rate="5Hz")
    assert len(starts) == 18_000
    assert starts == [k * 0.2 for k in range(18_000)]
    summed, t = [], 0.0
    for _ in range(18_000):
        summed.append(t)
        t += 0.2
    assert summed != starts           # the drift the engine does not have


def test_a_period_directive_starts_every_period_until_the_end(tmp_path: Path) -> None:
    """opspec:Period 10: starts at 0, 10, 20, 30 in 35 s; none at the end time itself."""
    assert _starts(tmp_path, 35.0, Period="10") == [0.0, 10.0, 20.0, 30.0]
    assert _starts(tmp_path, 30.0, Period="10") == [0.0, 10.0, 20.0]


def test_the_coverage_squares_are_the_power_operators() -> None:
    """The coverage test squares with ``math.pow(d, 2.0)`` (a C call when compiled) where the
    room's definition writes ``d ** 2``: the same double for every distance, negative ones
    included (the sign is taken off before the power either way)."""
    rng = random.Random(7)
    values = [rng.uniform(-10.0, 10.0) for _ in range(100_000)]
    values += [rng.uniform(-1e-3, 1e-3) for _ in range(20_000)]
    values += [0.0, -0.0, 0.125, -0.125, 1e-300, -1e-300, 1e154, -1e154]
    for d in values:
        assert math.pow(d, 2.0) == d ** 2, d


def test_cover_finds_the_cells_the_room_definition_finds() -> None:
    """``cover`` adds exactly the cells whose centre lies within reach plus half a cell
    (``RoomWorld._cover``'s test), in the order given, and leaves the others uncovered."""
    rng = random.Random(3)
    cell, reach = 0.25, 0.15
    for _ in range(2_000):
        x, y = rng.uniform(0.2, 4.8), rng.uniform(0.2, 3.8)
        cells = tuple((cx, cy) for cx in range(int((x - reach) // cell),
                                               int((x + reach) // cell) + 1)
                      for cy in range(int((y - reach) // cell), int((y + reach) // cell) + 1))
        covered = {c for c in cells if rng.random() < 0.3}
        before = set(covered)
        new, left = cover(cells, x, y, cell, reach, covered)
        expected = [(cx, cy) for cx, cy in cells if (cx, cy) not in before and (
            ((cx + 0.5) * cell - x) ** 2 + ((cy + 0.5) * cell - y) ** 2
            <= reach ** 2 + (cell / 2) ** 2)]
        assert new == expected
        assert covered == before | set(expected)
        assert left == tuple(c for c in cells if c not in covered)


class _Session:
    """What a performer's session does, for the room's devices: the time, the completions."""

    def __init__(self) -> None:
        self.now = 0.0
        self.done: list[dict[str, object] | None] = []

    def complete(self, item: WorkItem, data: dict[str, object] | None = None) -> None:
        self.done.append(data)

    def trace(self, kind: str, data: object = None) -> None:
        """World facts are not looked at here."""


def _item(n: int, application: str, data: dict[str, object] | None = None) -> WorkItem:
    return WorkItem(n, "robot", 1, application, application, "device", "device", 0.0,
                    application=application, data=data or {})


def test_the_range_readings_of_the_room_devices_are_the_rooms() -> None:
    """The compiled devices draw the range finder's noise from the room's generator as
    ``RoomWorld.op_read_range`` does: the same readings, bit for bit, draw after draw, with
    drives in between, as the room's own operation on a twin room of the same seed."""
    from opspec.worlds.device import devices_of

    fast_world = RoomWorld(np.random.default_rng(11))
    twin = RoomWorld(np.random.default_rng(11))
    devices = devices_of(fast_world)
    assert isinstance(devices, RoomDevices)
    session = _Session()
    devices.attach(session)
    commands = ["forward", "turn_left", "forward", "stop", "turn_random", "forward"]
    t = 0.0
    for n in range(600):
        t += 0.2
        session.now = t
        twin.advance(t)
        if n % 7 == 0:
            command = commands[(n // 7) % len(commands)]
            devices.offer(_item(2 * n, "drive", {"motor_cmd": command}))
            twin.op_drive({"motor_cmd": command})
        devices.offer(_item(2 * n + 1, "read_range"))
        expected = twin.op_read_range({})
        got = session.done[-1]
        assert got == expected, n
        assert (fast_world.robot.x, fast_world.robot.y, fast_world.robot.heading) == (
            twin.robot.x, twin.robot.y, twin.robot.heading)
