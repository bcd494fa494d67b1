"""Two participants of one profile bound to two ports (``--bind alarm=URL1 --bind
dispenser=URL2``): each participant's work goes to its own port. The engine used to route an
Application id to one binding only (the last registered, here the dispenser's), which played
the alarm's ``ALARM ON`` on the simulated device at once, while the summary said the alarm
was on its device with no fault; it now routes by the activity's participant
(``opspec.engine.registry.SharedApplication``), and a binding handed another participant's
work still passes it to that participant's port."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.bindings.attach import attach_devices
from opspec.cli import main

from .conftest import DEVICES
from .fakes import FakeSession, item, run_until

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
SILENT = "emulator://medication_dispenser?fault=silent"
WELL = "emulator://medication_dispenser"
# just past the 08:00 dose's first ALARM ON; at 10^6x its 500 ms timeout is far away
AT_THE_FIRST_ALARM = ["--until", "28800.01", "--speed", "1000000"]


def _devices(capsys: pytest.CaptureFixture[str], *binds: str) -> dict:
    args = [a for bind in binds for a in ("--bind", bind)]
    main(["run", str(SPEC), "--json", *AT_THE_FIRST_ALARM, *args])
    return json.loads(capsys.readouterr().out)["devices"]


def test_the_alarm_goes_to_the_alarms_port_when_the_dispenser_has_another(
        capsys: pytest.CaptureFixture[str]) -> None:
    devices = _devices(capsys, f"alarm={SILENT}", f"dispenser={WELL}")
    pending = devices["alarm"]["pending"]
    assert [(p["state"], p["command"]) for p in pending] == [("sent", "ALARM ON")]
    assert devices["dispenser"]["pending"] == []


def test_a_dispense_routed_to_the_alarms_binding_reaches_the_drawer() -> None:
    # work handed to the alarm's binding for the dispenser (as the engine once routed it)
    with attach_devices([f"dispenser={WELL}", f"alarm={SILENT}"], DEVICES,
                        settle_s=0) as devices:
        session = FakeSession()
        for binding in devices.bindings:
            binding.attach(session)
        drawer = item("dispense", "dispenser", slot=2)
        devices.performers["alarm"].offer(drawer)
        run_until(devices.inbox, session, lambda: bool(session.answered), timeout=5)
        assert session.completed == [(drawer, {"slot": 2})]
        assert [b.latency_summary().count for b in devices.bindings] == [1, 0]


def test_an_unbound_participant_of_the_profile_is_still_simulated(
        capsys: pytest.CaptureFixture[str]) -> None:
    # only the dispenser bound: the alarm's ALARM ON, routed to its binding, is simulated
    devices = _devices(capsys, f"dispenser={SILENT}")
    assert devices["dispenser"]["pending"] == []
    assert devices["dispenser"]["latency_ms"]["count"] == 0
