"""``[fallback] scope``: ``run`` keeps a participant on the simulated device for the rest of
the run once a command ran out of retries; ``command`` simulates only that command and sends
the next one to the device again (the shipped dispenser's alarm)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from opspec.bindings import DeviceBinding
from opspec.bindings.profiles import load_profile
from opspec.errors import BindingError

from .conftest import DATA, DEVICES
from .fakes import FakeSession, item, run_until

Binder = Callable[..., DeviceBinding]
PARTS = ["alarm", "dispenser", "user"]


def _profile_with(tmp_path: Path, scope: str) -> Path:
    text = (DATA / "test_dispenser.toml").read_text(encoding="utf-8")
    text = text.replace('then = "simulate"\n', f'then = "simulate"\nscope = "{scope}"\n', 1)
    path = tmp_path / "test_dispenser.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("scope", ["command", "run"])
def test_a_lost_alarm_is_simulated_once_or_for_the_rest_of_the_run(
        binder: Binder, session: FakeSession, tmp_path: Path, scope: str) -> None:
    path = _profile_with(tmp_path, scope)
    profile = load_profile(path)
    assert profile.fallback_for("alarm").scope == scope
    binding = binder(PARTS, f"emulator://{path}?fault=silent:2", profile)
    first = item("alarm_on")
    binding.offer(first)                      # both attempts unanswered
    run_until(binding.inbox, session, lambda: bool(session.answered))
    session.advance()
    assert session.completed == [(first, None)]   # by the simulated alarm
    assert [(f["fault"], f["action"]) for f in session.kinds("fault")] == [
        ("timeout", "retry"), ("timeout", "simulate")]
    second = item("alarm_on")
    binding.offer(second)
    run_until(binding.inbox, session, lambda: len(session.answered) == 2)
    session.advance()
    assert session.completed[-1] == (second, None)
    answered_by_device = bool(binding.latencies)
    if scope == "command":
        assert binding.mode("alarm") == "device" and answered_by_device
    else:
        assert binding.mode("alarm") == "simulated" and not answered_by_device


def test_the_shipped_alarm_falls_back_per_command_and_the_drawer_never_resends() -> None:
    profile = load_profile(DEVICES / "medication_dispenser.toml")
    alarm, drawer = profile.fallback_for("alarm"), profile.fallback_for("dispenser")
    assert (alarm.retries, alarm.then, alarm.scope) == (1, "simulate", "command")
    assert (drawer.retries, drawer.then, drawer.exception) == (0, "abort", "DispenserFault")
    assert "slot" not in profile.operations["dispense"].defaults


def test_an_unknown_scope_is_refused(tmp_path: Path) -> None:
    with pytest.raises(BindingError, match="scope"):
        load_profile(_profile_with(tmp_path, "forever"))
