"""The behaviour-based specs with their motors, range finder and bumper bound to emulated
boards on sockets: the shipped profiles speak the specs' applications (``drive`` with the
arbitrated ``motor_cmd``, ``read_range`` in metres, ``read_bump`` as a boolean), the world
simulates what is not bound, and the run follows the wall clock."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from opspec.bindings import load_profile
from opspec.bindings.emulator import EmulatedDevice, Reply, SocketEmulator
from opspec.cli import main

from .conftest import DEVICES

VACUUM = DEVICES.parent / "specs" / "vacuum_cleaner.xpdl"


class Motors(EmulatedDevice):
    """The motors board, which remembers whether it was told to back up."""

    backed_up = False

    def handle_line(self, line: str) -> list[Any]:
        if line == "DRIVE back":
            self.backed_up = True
        return super().handle_line(line)


class PressedAgainstAWall(EmulatedDevice):
    """A bumper that reports a contact from its second reading on, until the motors have been
    told to back up: a contact the spec cannot miss however late the run's readings come (a
    contact reported once is overwritten by the next reading when the machine is so busy that
    the manoeuvre's period comes after it, which CI saw)."""

    def __init__(self, profile: Any, motors: Motors) -> None:
        super().__init__(profile)
        self.motors = motors

    def handle_line(self, line: str) -> list[Any]:
        actions = super().handle_line(line)
        if line == "BUMP?" and self.commands >= 2 and not self.motors.backed_up:
            return [Reply(self.encode("BUMP 1"))]
        return actions


@pytest.fixture
def boards() -> Iterator[dict[str, SocketEmulator]]:
    motors = Motors(load_profile(DEVICES / "cart_motors.toml"))
    servers = {
        "motors": SocketEmulator(motors),
        "range_finder": SocketEmulator(
            EmulatedDevice(load_profile(DEVICES / "range_finder.toml"))),
        "bumper": SocketEmulator(PressedAgainstAWall(load_profile(DEVICES / "bumper.toml"),
                                                     motors)),
    }
    for server in servers.values():
        server.start()
    yield servers
    for server in servers.values():
        server.stop()


def test_vacuum_cleaner_drives_real_boards_in_wall_clock_time(
        boards: dict[str, SocketEmulator], capsys: pytest.CaptureFixture[str],
        tmp_path: Path) -> None:
    trace = tmp_path / "trace.jsonl"
    binds = [arg for name, server in boards.items()
             for arg in ("--bind", f"{name}={server.url}")]
    status = main(["run", str(VACUUM), "--until", "4", "--realtime", "--speed", "8",
                   "--json", "--trace", str(trace), *binds])
    doc = json.loads(capsys.readouterr().out)
    assert status == 0
    for name in boards:                       # 5 Hz sensing and driving for 4 s
        assert doc["devices"][name]["mode"] == {name: "device"}
        assert doc["devices"][name]["latency_ms"]["count"] >= 15
        assert doc["devices"][name]["faults"] == []
    events = [json.loads(line) for line in trace.read_text().splitlines()[1:]]
    exchanges = [e["data"] for e in events if e["kind"] == "device.exchange"]
    commands = {x["command"] for x in exchanges if x["device"] == "cart_motors"}
    assert "DRIVE forward" in commands        # the arbiter's named command goes to the board
    ranges = [e for e in events if e["kind"] == "data.changed"
              and (e.get("data") or {}).get("distance") == 1.23]
    assert ranges                             # the board's reading reached the spec's data
    # the contact the bumper board reported started the manoeuvre
    assert doc["metrics"]["manoeuvres"]["total"] >= 1
    assert doc["drift"]["events"] > 0
