"""`opspec run --bind` with a real device and no --speed runs at 1x: the note says how long
that takes in wall time, since the default horizon is a day and the run otherwise looks hung."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from opspec.bindings.attach import attach_devices
from opspec.bindings.profiles import DeviceProfile
from opspec.engine.config import EngineConfig

from .conftest import DEVICES


def test_the_note_says_how_long_the_run_takes_on_the_wall_clock(
        emulate: Callable[..., Any], dispenser_profile: DeviceProfile) -> None:
    server = emulate(dispenser_profile, on="socket")
    with attach_devices([f"alarm={server.url}"], DEVICES) as devices:
        config, note = devices.clock(EngineConfig(), None, 86400.0)
        assert config.realtime and config.speed == 1.0
        assert note == ("a real device is bound: running on the wall clock at 1x, so the run "
                        "takes 1 day of wall time (--until or --speed shortens it; Ctrl+C "
                        "stops it)")
        assert "takes 1 h of wall time" in devices.clock(EngineConfig(), 24.0, 86400.0)[1]
