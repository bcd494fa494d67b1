"""Binding participants: explicit ports, ``auto`` with its simulated fallback, and the
``--bind PARTICIPANT=URL`` arguments."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest

from opspec.bindings import DEVICE_NOTE, DeviceBinding, bind, bindings_from_args
from opspec.bindings.emulator import PtyEmulator, SocketEmulator
from opspec.bindings.profiles import DeviceProfile
from opspec.bindings.transport import PortInfo
from opspec.errors import BindingError

from .conftest import DEVICES, needs_pty
from .fakes import FakeSession, item, run_until

Binder = Callable[..., DeviceBinding]


def test_explicit_port_that_cannot_be_opened_stops_before_the_run(
        dispenser_profile: DeviceProfile) -> None:
    with pytest.raises(BindingError, match=re.escape(
            "alarm: cannot open /dev/ttyOPSPEC9: [Errno 2] No such file or directory")):
        bind("alarm", "/dev/ttyOPSPEC9", dispenser_profile)


def test_refused_socket_names_the_url_and_the_reason(dispenser_profile: DeviceProfile) -> None:
    with pytest.raises(BindingError, match=r"cannot open socket://127.0.0.1:1: .*refused"):
        bind("alarm", "socket://127.0.0.1:1", dispenser_profile)


def test_unknown_url_scheme_is_explained(dispenser_profile: DeviceProfile) -> None:
    with pytest.raises(BindingError, match="protocol 'usb' not known"):
        bind("alarm", "usb://thing", dispenser_profile)


def test_participant_the_profile_does_not_serve_is_refused(
        dispenser_profile: DeviceProfile) -> None:
    with pytest.raises(BindingError, match="does not serve participant 'motors'"):
        bind("motors", "loop://", dispenser_profile)


def test_auto_without_a_matching_port_uses_the_simulated_device_and_says_so(
        binder: Binder, session: FakeSession, dispenser_profile: DeviceProfile) -> None:
    binding = binder("alarm", "auto", dispenser_profile, ports=[
        PortInfo("/dev/ttyUSB0", "FT232R", "USB VID:PID=0403:6001", 0x0403, 0x6001)])
    assert binding.simulated and not binding.requires_wall_clock
    assert binding.notes == [
        "alarm: no device matched VID:PID 2341:0043, using the simulated alarm"]
    assert [n["message"] for n in session.kinds(DEVICE_NOTE)] == binding.notes
    on = item("alarm_on")
    binding.offer(on)
    session.advance()
    assert session.completed == [(on, None)]


@needs_pty
def test_auto_binds_the_port_whose_usb_ids_match(
        binder: Binder, emulate: Callable[..., PtyEmulator | SocketEmulator],
        session: FakeSession, dispenser_profile: DeviceProfile) -> None:
    emulator = emulate(dispenser_profile, on="pty")
    ports = [PortInfo("/dev/ttyS0", "n/a", "n/a"),
             PortInfo(emulator.url, "Arduino Uno", "USB VID:PID=2341:0043", 0x2341, 0x0043)]
    binding = binder(["alarm"], "auto", dispenser_profile, ports=ports)
    assert binding.url == emulator.url and not binding.simulated
    assert "matched VID:PID 2341:0043" in binding.notes[0]
    binding.offer(item("alarm_on"))
    run_until(binding.inbox, session, lambda: bool(session.answered))
    assert session.faults() == []


def test_auto_with_a_matching_port_that_will_not_open_falls_back(
        binder: Binder, dispenser_profile: DeviceProfile) -> None:
    ports = [PortInfo("/dev/ttyOPSPEC7", "Arduino", "", 0x2341, 0x0043)]
    binding = binder(["alarm"], "auto", dispenser_profile, ports=ports)
    assert binding.simulated
    assert "cannot open /dev/ttyOPSPEC7" in binding.notes[0]
    assert binding.notes[0].endswith("using the simulated alarm")


def test_bind_args_group_participants_of_one_device_on_one_port(tmp_path: Path) -> None:
    url = "emulator://medication_dispenser"
    made = bindings_from_args([f"alarm={url}", f"dispenser={url}"], DEVICES, settle_s=0)
    try:
        assert len(made) == 1
        assert made[0].participants == ("alarm", "dispenser")
    finally:
        for binding in made:
            binding.close()


def test_bind_args_share_one_inbox(dispenser_profile: DeviceProfile) -> None:
    made = bindings_from_args(["alarm=auto", "range_finder=auto"], DEVICES, ports=[])
    try:
        assert len(made) == 2 and made[0].inbox is made[1].inbox
        assert all(b.simulated for b in made)
    finally:
        for binding in made:
            binding.close()


@pytest.mark.parametrize(("specs", "words"), [
    (["alarm"], "cannot read --bind 'alarm'"),
    (["=loop://"], "cannot read --bind"),
    (["alarm:=loop://"], "empty profile"),
    (["alarm=auto", "alarm=loop://"], "participant 'alarm' is bound twice"),
    (["pump=auto"], "no device profile in .* serves participant 'pump'"),
    (["alarm:teapot=auto"], "no profile named 'teapot'"),
    (["alarm:cart_motors=auto"], "profile 'cart_motors' does not serve 'alarm'"),
    (["alarm=loop://", "motors=loop://"], "port loop:// is bound to two profiles"),
    (["alarm=/dev/ttyOPSPEC9"], "alarm: cannot open /dev/ttyOPSPEC9"),
], ids=["no-equals", "no-participant", "empty-profile", "bound-twice", "unknown-participant",
        "unknown-profile", "profile-does-not-serve", "port-claimed-twice", "missing-port"])
def test_bad_bind_arguments_are_explained(specs: list[str], words: str) -> None:
    with pytest.raises(BindingError, match=words):
        bindings_from_args(specs, DEVICES)


def test_ambiguous_participant_asks_for_a_profile(tmp_path: Path) -> None:
    text = (DEVICES / "medication_dispenser.toml").read_text()
    (tmp_path / "a.toml").write_text(text.replace('name = "medication_dispenser"', 'name = "a"'))
    (tmp_path / "b.toml").write_text(text.replace('name = "medication_dispenser"', 'name = "b"'))
    with pytest.raises(BindingError, match=re.escape("pick one: alarm:a=auto")):
        bindings_from_args(["alarm=auto"], tmp_path)


def test_the_help_of_bind_shows_the_profile_form_and_the_kinds_of_url(capsys) -> None:
    """``PARTICIPANT:PROFILE=URL`` (devices/README.md) was not in ``--help``: a participant
    that several profiles serve could not be bound from what the help said."""
    import pytest

    from opspec.cli import main

    with pytest.raises(SystemExit):
        main(["run", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "--bind PARTICIPANT[:PROFILE]=URL" in out
    assert "socket://HOST:PORT" in out and "emulator://PROFILE" in out
