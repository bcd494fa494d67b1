"""The room's compiled performer (opspec/worlds/room_devices.py) runs a robot spec exactly as
the general one (``WorldDevices`` asking the room's ``op_`` methods): the same trace, event
for event, bit for bit -- readings, coverage, collisions, the random turns, the battery.

A run's trace must not depend on which performer answered the device operations (the
project's rule for every speed-up: "the same seeds give the same traces and numbers")."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from opspec.engine.compiled import compile_package
from opspec.engine.simulation import Simulation
from opspec.worlds import world_performers
from opspec.worlds.device import WorldDevices
from opspec.worlds.room_devices import RoomDevices
from opspec.xpdl.open_spec import open_spec

SPECS = Path(__file__).resolve().parents[2] / "specs"


def _trace(spec: str, seed: int, general: bool) -> list[Any]:
    compiled = compile_package(open_spec(SPECS / spec))
    performers: dict[str, Any] = dict(world_performers(compiled, seed=seed, user=0))
    assert isinstance(performers["world"], RoomDevices)
    if general:
        performers["world"] = WorldDevices(performers["world"].world)
    result = Simulation(compiled, performers=performers, seed=seed, keep_trace=True).run(
        until=240.0)
    assert result.trace is not None
    return [(e.time.hex(), e.kind, e.process, e.instance, e.activity, repr(e.data))
            for e in result.trace]


@pytest.mark.parametrize(("spec", "seed"), [("vacuum_cleaner.xpdl", 3),
                                            ("vacuum_cleaner.xpdl", 11),
                                            ("medication_cart_guidance.xpdl", 3)])
def test_the_compiled_room_performer_gives_the_general_ones_trace(spec: str,
                                                                  seed: int) -> None:
    fast, general = _trace(spec, seed, False), _trace(spec, seed, True)
    assert fast == general
    kinds = {row[1] for row in fast}
    # the run did use the room: readings, coverage and (the vacuum cleaner) collisions
    assert "world.covered" in kinds and len(fast) > 5000
    if spec.startswith("vacuum"):
        assert "world.collision" in kinds
