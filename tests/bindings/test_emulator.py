"""The emulated device: replies per profile and scripted misbehaviour."""

from __future__ import annotations

import pytest

from opspec.bindings.emulator import DISCONNECT, GARBAGE, Behaviour, EmulatedDevice, Reply
from opspec.bindings.profiles import DeviceProfile, load_profile
from opspec.errors import BindingError

from .conftest import DEVICES


@pytest.fixture
def range_finder() -> DeviceProfile:
    return load_profile(DEVICES / "range_finder.toml")


def test_replies_follow_the_profile(dispenser_profile: DeviceProfile,
                                    range_finder: DeviceProfile) -> None:
    device = EmulatedDevice(dispenser_profile)
    assert device.handle_line("ALARM ON") == [Reply(b"OK\n")]
    assert device.handle_line("DISPENSE 4") == [Reply(b"OK DISPENSED 4\n")]
    assert device.handle_line("MAKE COFFEE") == [Reply(b"ERR UNKNOWN\n")]
    assert EmulatedDevice(range_finder).handle_line("RANGE?") == [Reply(b"RANGE 1.23\n")]


def test_cart_motors_use_crlf(dispenser_profile: DeviceProfile) -> None:
    device = EmulatedDevice(load_profile(DEVICES / "cart_motors.toml"))
    assert device.handle_line("MOTOR 50 -50") == [Reply(b"OK\r\n")]
    assert device.handle_line("DRIVE turn_left") == [Reply(b"OK\r\n")]
    assert device.event_line("bump") == b"BUMP FRONT\r\n"


@pytest.mark.parametrize(("spec", "replies"), [
    ("silent:2", [[], [], [Reply(b"OK\n")]]),
    ("garbage", [[Reply(GARBAGE + b"\n")]] * 3),
    ("late:250", [[Reply(b"OK\n", 0.25)]] * 3),
    ("disconnect:1", [[Reply(b"OK\n")], [DISCONNECT], [Reply(b"OK\n")]]),
    ("error:ERR JAM", [[Reply(b"ERR JAM\n")]] * 3),
], ids=["silent-first-two", "garbage", "late", "disconnect-once", "error-line"])
def test_scripted_behaviours(dispenser_profile: DeviceProfile, spec: str,
                             replies: list[list[object]]) -> None:
    device = EmulatedDevice(dispenser_profile, Behaviour.parse(spec))
    assert [device.handle_line("ALARM ON") for _ in replies] == replies


@pytest.mark.parametrize("spec", ["loud", "late", "late:soon", "disconnect", "error:",
                                  "none:3"])
def test_unknown_fault_specs_are_explained(spec: str) -> None:
    with pytest.raises(BindingError, match="use none, silent"):
        Behaviour.parse(spec)


def test_unknown_event_lists_the_profiles_events(dispenser_profile: DeviceProfile) -> None:
    with pytest.raises(BindingError, match="has no event 'alarm'.*events: report"):
        EmulatedDevice(dispenser_profile).event_line("alarm")
