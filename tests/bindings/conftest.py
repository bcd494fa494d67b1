"""Fixtures for binding tests: profiles, emulators on real transports, bindings that are
always closed, and the fake engine session."""

from __future__ import annotations

import os
import tty
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from opspec.bindings import DeviceBinding, bind, load_profile
from opspec.bindings.emulator import Behaviour, EmulatedDevice, PtyEmulator, SocketEmulator
from opspec.bindings.profiles import DeviceProfile

from .board_runs import BoardRun, run_all
from .fakes import FakeSession

DEVICES = Path(__file__).resolve().parents[2] / "devices"
DATA = Path(__file__).parent / "data"


@pytest.fixture
def dispenser_profile() -> DeviceProfile:
    """The shipped medication dispenser profile."""
    return load_profile(DEVICES / "medication_dispenser.toml")


@pytest.fixture
def fast_profile() -> DeviceProfile:
    """The dispenser with 300 ms reply timeouts, for fault tests."""
    return load_profile(DATA / "test_dispenser.toml")


@pytest.fixture
def fast_url() -> Callable[[str], str]:
    """``emulator://`` URL of the fast profile with a fault spec."""
    return lambda fault="none": f"emulator://{DATA / 'test_dispenser.toml'}?fault={fault}"


@pytest.fixture
def session() -> FakeSession:
    return FakeSession()


@pytest.fixture
def binder(session: FakeSession) -> Iterator[Callable[..., DeviceBinding]]:
    """``binder(participants, url, profile)``: bind (no settle wait), attach to ``session``,
    and close at teardown whatever happens."""
    made: list[DeviceBinding] = []

    def make(participants: Any, url: str, profile: DeviceProfile, **kw: Any) -> DeviceBinding:
        binding = bind(participants, url, profile, settle_s=0, **kw)
        made.append(binding)
        binding.attach(session)
        return binding

    yield make
    for binding in made:
        binding.close()


def _pty_available() -> bool:
    try:
        master, slave = os.openpty()
    except OSError:
        return False
    os.close(master)
    os.close(slave)
    return True


needs_pty = pytest.mark.skipif(not _pty_available(),
                               reason="os.openpty() is unavailable here (no /dev/ptmx)")


@pytest.fixture
def emulate() -> Iterator[Callable[..., PtyEmulator | SocketEmulator]]:
    """``emulate(profile, fault="none", on="pty"|"socket")``: a running emulator, stopped at
    teardown."""
    servers: list[PtyEmulator | SocketEmulator] = []

    def start(profile: DeviceProfile, fault: str = "none",
              on: str = "pty") -> PtyEmulator | SocketEmulator:
        device = EmulatedDevice(profile, Behaviour.parse(fault))
        server = PtyEmulator(device) if on == "pty" else SocketEmulator(device)
        servers.append(server)
        server.start()
        return server

    yield start
    for server in servers:
        server.stop()


@pytest.fixture(scope="session")
def board_runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, BoardRun]:
    """Every scenario of board_runs.SCENARIOS, run side by side once per test process (the
    tests that ask need socat and a pty: they skip before asking)."""
    return run_all(tmp_path_factory.mktemp("board-runs"))

@pytest.fixture
def raw_pty() -> Iterator[tuple[int, str]]:
    """A pseudo-terminal whose device side the test writes by hand."""
    try:
        master, slave = os.openpty()
    except OSError:
        pytest.skip("os.openpty() is unavailable here")
    tty.setraw(slave)
    yield master, os.ttyname(slave)
    os.close(master)
    os.close(slave)
