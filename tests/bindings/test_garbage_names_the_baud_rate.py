"""Garbage on a serial line names the profile's baud rate: a designer whose board runs at
9600 while the profile says 115200 sees undecodable bytes, and the fault said nothing of
where to look. Network URLs have no baud rate: not said there."""

from __future__ import annotations

import os
from collections.abc import Callable

from opspec.bindings import DeviceBinding
from opspec.bindings.emulator import PtyEmulator, SocketEmulator
from opspec.bindings.profiles import DeviceProfile

from .fakes import FakeSession, item, run_until

Binder = Callable[..., DeviceBinding]
Emulate = Callable[..., PtyEmulator | SocketEmulator]


def test_undecodable_bytes_on_a_serial_line_name_the_baud_rate(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        raw_pty: tuple[int, str]) -> None:
    master, path = raw_pty
    binding = binder(["alarm"], path, fast_profile)
    os.write(master, b"\xff\xfe\x81\x9a\n")
    run_until(binding.inbox, session, lambda: bool(session.faults()))
    message = session.kinds("fault")[0]["message"]
    assert (f"garbled data from {path} (not ascii text; is 115200 baud, the profile's "
            "[serial] baudrate, the device's?)") in message


def test_garbage_in_reply_to_a_command_names_it_too(
        binder: Binder, emulate: Emulate, session: FakeSession,
        fast_profile: DeviceProfile) -> None:
    emulator = emulate(fast_profile, fault="garbage:1", on="pty")
    binding = binder(["alarm"], emulator.url, fast_profile)
    binding.offer(item("alarm_on"))
    run_until(binding.inbox, session, lambda: bool(session.answered))
    garbage = [f for f in session.kinds("fault") if f["fault"] == "garbage"]
    assert garbage and "baud" in garbage[0]["message"]


def test_a_socket_has_no_baud_rate_to_blame(
        binder: Binder, emulate: Emulate, session: FakeSession,
        fast_profile: DeviceProfile) -> None:
    emulator = emulate(fast_profile, fault="garbage:1", on="socket")
    binding = binder(["alarm"], emulator.url, fast_profile)
    binding.offer(item("alarm_on"))
    run_until(binding.inbox, session, lambda: bool(session.answered))
    garbage = [f for f in session.kinds("fault") if f["fault"] == "garbage"]
    assert garbage and "baud" not in garbage[0]["message"]
