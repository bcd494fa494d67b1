"""A designer's mistakes when opening ports: a port another run already has open, an
``emulator://`` profile kept in a ``--devices`` folder, and what the refusal tells them to
check for each kind of URL."""

from __future__ import annotations

import os
import socket
from pathlib import Path

import pytest

from opspec.bindings import bind, bindings_from_args
from opspec.bindings.profiles import DeviceProfile
from opspec.errors import BindingError

from .conftest import DEVICES, needs_pty


@pytest.fixture
def pty_path() -> object:
    """The slave side of a fresh pseudo-terminal (what `opspec devices emulate` prints)."""
    master, slave = os.openpty()
    try:
        yield os.ttyname(slave)
    finally:
        os.close(slave)
        os.close(master)


@needs_pty
def test_a_port_another_run_has_open_is_refused_as_busy(
        dispenser_profile: DeviceProfile, pty_path: str) -> None:
    # two runs on one board each read part of the other's replies: both saw garbage
    first = bind("alarm", pty_path, dispenser_profile, settle_s=0)
    try:
        with pytest.raises(BindingError) as refused:
            bind("alarm", pty_path, dispenser_profile, settle_s=0)
        assert refused.value.message == f"alarm: cannot open {pty_path}: it is in use by " \
            "another program"
        assert "close the other program" in refused.value.hint
    finally:
        first.close()


@needs_pty
def test_the_port_opens_again_once_the_first_run_closed_it(
        dispenser_profile: DeviceProfile, pty_path: str) -> None:
    bind("alarm", pty_path, dispenser_profile, settle_s=0).close()
    bind("alarm", pty_path, dispenser_profile, settle_s=0).close()


def _closed_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def test_a_refused_socket_says_to_start_the_server_not_to_check_a_cable(
        dispenser_profile: DeviceProfile) -> None:
    with pytest.raises(BindingError) as refused:
        bind("alarm", f"socket://127.0.0.1:{_closed_port()}", dispenser_profile)
    assert "listening" in refused.value.hint and "opspec devices emulate" in refused.value.hint
    assert "cable" not in refused.value.hint and "dialout" not in refused.value.hint


def test_a_misspelt_emulator_profile_says_how_to_write_the_url(
        dispenser_profile: DeviceProfile) -> None:
    with pytest.raises(BindingError) as refused:
        bind("alarm", "emulator://medicaton_dispenser", dispenser_profile)
    assert "no device profile named 'medicaton_dispenser'" in refused.value.message
    assert "emulator://PROFILE" in refused.value.hint and "cable" not in refused.value.hint


def test_a_device_path_that_does_not_exist_still_says_cable_and_permissions(
        dispenser_profile: DeviceProfile) -> None:
    with pytest.raises(BindingError) as refused:
        bind("alarm", "/dev/ttyOPSPEC9", dispenser_profile)
    assert "cable" in refused.value.hint and "dialout" in refused.value.hint


def _board_folder(tmp_path: Path) -> Path:
    text = (DEVICES / "medication_dispenser.toml").read_text(encoding="utf-8")
    (tmp_path / "my_board.toml").write_text(
        text.replace('name = "medication_dispenser"', 'name = "my_board"'), encoding="utf-8")
    return tmp_path


def test_emulator_finds_a_profile_of_the_devices_folder(tmp_path: Path) -> None:
    # `--devices DIR --bind alarm=emulator://my_board`: the emulator looked in ./devices only
    folder = _board_folder(tmp_path)
    made = bindings_from_args(["alarm=emulator://my_board"], folder, settle_s=0)
    try:
        assert [b.profile.name for b in made] == ["my_board"]
        assert made[0].requires_wall_clock          # a port is open: the emulator
    finally:
        for binding in made:
            binding.close()


def test_emulator_still_finds_the_shipped_profiles_beside_a_devices_folder(
        tmp_path: Path) -> None:
    folder = _board_folder(tmp_path)
    made = bindings_from_args(["alarm=emulator://medication_dispenser"], folder, settle_s=0)
    for binding in made:
        binding.close()


def test_emulator_profile_missing_everywhere_lists_the_devices_folder(tmp_path: Path) -> None:
    folder = _board_folder(tmp_path)
    with pytest.raises(BindingError, match=f"no device profile named 'my_boar' in {tmp_path}"
                       r".*available: my_board"):
        bindings_from_args(["alarm=emulator://my_boar"], folder, settle_s=0)


def test_a_refused_socket_says_the_reason_once(dispenser_profile: DeviceProfile) -> None:
    # was "cannot open socket://…: Could not open port socket://…: [Errno 111] …"
    url = f"socket://127.0.0.1:{_closed_port()}"
    with pytest.raises(BindingError) as refused:
        bind("alarm", url, dispenser_profile)
    assert refused.value.message.startswith(f"alarm: cannot open {url}: [Errno ")
    assert "Could not open port" not in refused.value.message


def test_only_a_device_path_of_a_board_is_waited_for_after_opening(tmp_path) -> None:
    """The profile's settle_ms is for boards that reset when their port opens; a
    pseudo-terminal (`opspec devices emulate`'s, a socat pair) resets nothing, and binding
    one waited 2 s for nothing; pySerial URLs never waited."""
    import os
    import pty

    from opspec.bindings.transport import settles

    leader, follower = pty.openpty()
    try:
        name = os.ttyname(follower)
        link = tmp_path / "board"
        link.symlink_to(name)                     # a stable name for the pty, as socat makes
        assert not settles(name) and not settles(str(link))
    finally:
        os.close(leader)
        os.close(follower)
    assert not settles("socket://127.0.0.1:4000") and not settles("emulator://bumper")
    assert settles("/dev/ttyACM0") and settles("/dev/ttyUSB0") and settles("COM3")


@needs_pty
def test_binding_an_emulator_on_a_pseudo_terminal_does_not_wait_the_boards_settle(
        emulate, monkeypatch) -> None:
    """The shipped dispenser profile waits 2 s after opening a board's port (an Uno resets);
    bound to `opspec devices emulate`'s pseudo-terminal it waited those 2 s for nothing."""
    import importlib

    from opspec.bindings import load_profile

    binding_module = importlib.import_module("opspec.bindings.bind")   # (bind: the function)

    profile = load_profile(DEVICES / "medication_dispenser.toml")
    assert profile.serial.settle_s == 2.0
    waits: list[float] = []
    monkeypatch.setattr(binding_module.time, "sleep", waits.append)
    server = emulate(profile)
    binding = binding_module.bind(["dispenser"], server.path, profile)
    try:
        assert waits == []
    finally:
        binding.close()
