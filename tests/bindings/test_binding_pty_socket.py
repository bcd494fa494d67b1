"""The dispenser's alarm, drawer and report button bound to an emulator over a real
pseudo-terminal pair (``os.openpty``) and over ``socket://`` on localhost."""

from __future__ import annotations

import os
from collections.abc import Callable

from opspec.bindings import DEVICE_NOTE, DeviceBinding
from opspec.bindings.emulator import PtyEmulator, SocketEmulator
from opspec.bindings.profiles import DeviceProfile

from .conftest import needs_pty
from .fakes import FakeSession, item, run_until

Binder = Callable[..., DeviceBinding]
Emulate = Callable[..., PtyEmulator | SocketEmulator]


@needs_pty
def test_dispenser_over_a_pseudo_terminal(binder: Binder, emulate: Emulate,
                                          session: FakeSession,
                                          dispenser_profile: DeviceProfile) -> None:
    emulator = emulate(dispenser_profile, on="pty")
    binding = binder(["alarm", "dispenser"], emulator.url, dispenser_profile)
    on, drawer, off = item("alarm_on"), item("dispense", "dispenser", slot=2), item("alarm_off")
    for work in (on, drawer, off):
        binding.offer(work)
    run_until(binding.inbox, session, lambda: len(session.answered) == 3)
    assert session.completed == [(on, None), (drawer, {"slot": 2}), (off, None)]
    assert emulator.received == ["ALARM ON", "DISPENSE 2", "ALARM OFF"]
    assert len(binding.latencies) == 3 and session.faults() == []


@needs_pty
def test_button_press_on_the_pty_raises_trg_1(binder: Binder, emulate: Emulate,
                                              session: FakeSession,
                                              dispenser_profile: DeviceProfile) -> None:
    emulator = emulate(dispenser_profile, on="pty")
    binding = binder(["alarm", "dispenser"], emulator.url, dispenser_profile)
    emulator.send_event("report")
    run_until(binding.inbox, session, lambda: bool(session.triggers))
    assert session.triggers == [("trg_1", None)]
    assert session.faults() == []


@needs_pty
def test_pty_vanishing_mid_run_falls_back_per_participant(
        binder: Binder, emulate: Emulate, session: FakeSession,
        fast_profile: DeviceProfile) -> None:
    emulator = emulate(fast_profile, fault="disconnect:1", on="pty")
    binding = binder(["alarm", "dispenser"], emulator.url, fast_profile)
    on, drawer = item("alarm_on"), item("dispense", "dispenser", slot=1)
    binding.offer(on)
    binding.offer(drawer)  # the emulator drops the line on this one; the path disappears
    run_until(binding.inbox, session, lambda: len(session.answered) == 2)
    assert session.completed == [(on, None)]
    assert [(f[0], f[1]) for f in session.failed] == [(drawer, "DispenserFault")]
    assert [(f["fault"], f["action"]) for f in session.kinds("fault")] == [
        ("disconnected", "reconnect"), ("reconnect-failed", "abort/simulate")]
    assert "cannot reopen" in session.kinds("fault")[1]["message"]
    assert (binding.mode("alarm"), binding.mode("dispenser")) == ("simulated", "aborted")
    assert not binding.requires_wall_clock
    # afterwards: the alarm is simulated, the drawer fails at once; nothing hangs
    off, again = item("alarm_off"), item("dispense", "dispenser", slot=1)
    binding.offer(off)
    binding.offer(again)
    session.advance()
    assert session.completed[-1] == (off, None)
    assert session.failed[-1][:2] == (again, "DispenserFault")
    assert session.faults()[-1] == "unavailable"


def test_unexpected_and_garbled_lines_while_idle_are_faults(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        raw_pty: tuple[int, str]) -> None:
    master, path = raw_pty
    binding = binder(["alarm"], path, fast_profile)
    os.write(master, b"# booting\nHELLO?\n\xff\xfe\x01\n")
    run_until(binding.inbox, session, lambda: len(session.faults()) == 2)
    assert session.faults() == ["unexpected-line", "garbage"]  # '# booting' is ignored
    assert "unexpected line 'HELLO?'" in session.kinds("fault")[0]["message"]


def test_overlong_line_without_terminator_is_garbage(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        raw_pty: tuple[int, str]) -> None:
    master, path = raw_pty
    binding = binder(["alarm"], path, fast_profile)
    os.write(master, b"X" * 300)
    run_until(binding.inbox, session, lambda: bool(session.faults()))
    assert session.faults() == ["garbage"]
    assert "no line terminator within 256 bytes" in session.kinds("fault")[0]["message"]


def test_dispenser_over_a_socket(binder: Binder, emulate: Emulate, session: FakeSession,
                                 dispenser_profile: DeviceProfile) -> None:
    emulator = emulate(dispenser_profile, on="socket")
    assert emulator.url.startswith("socket://127.0.0.1:")
    binding = binder(["alarm", "dispenser"], emulator.url, dispenser_profile)
    on, drawer = item("alarm_on"), item("dispense", "dispenser", slot=5)
    binding.offer(on)
    binding.offer(drawer)
    emulator.send_event("report")
    run_until(binding.inbox, session,
              lambda: len(session.answered) == 2 and bool(session.triggers))
    assert session.completed == [(on, None), (drawer, {"slot": 5})]
    assert session.triggers == [("trg_1", None)]


def test_socket_disconnect_reconnects_and_the_command_succeeds(
        binder: Binder, emulate: Emulate, session: FakeSession,
        fast_profile: DeviceProfile) -> None:
    emulator = emulate(fast_profile, fault="disconnect:0", on="socket")
    binding = binder(["alarm", "dispenser"], emulator.url, fast_profile)
    drawer = item("dispense", "dispenser", slot=3)
    binding.offer(drawer)
    run_until(binding.inbox, session, lambda: bool(session.answered))
    assert session.completed == [(drawer, {"slot": 3})]
    assert session.faults() == ["disconnected"]
    assert any("reconnected to socket://" in n["message"] for n in session.kinds(DEVICE_NOTE))
    assert emulator.received == ["DISPENSE 3", "DISPENSE 3"]


def test_socket_late_reply_within_the_timeout_is_fine(
        binder: Binder, emulate: Emulate, session: FakeSession,
        dispenser_profile: DeviceProfile) -> None:
    emulator = emulate(dispenser_profile, fault="late:50", on="socket")
    binding = binder(["alarm"], emulator.url, dispenser_profile)
    binding.offer(item("alarm_on"))
    run_until(binding.inbox, session, lambda: bool(session.answered))
    assert session.faults() == []
    assert binding.latencies[0] >= 0.05
