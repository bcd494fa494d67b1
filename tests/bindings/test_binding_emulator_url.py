"""A DeviceBinding against the in-process scripted device (``emulator://``, built on
``loop://``) and plain ``loop://``: the protocol, every fault and every fallback."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from opspec.bindings import DEVICE_EXCHANGE, DEVICE_NOTE, DeviceBinding
from opspec.bindings.profiles import DeviceProfile, load_profile
from opspec.engine.performers import Performer

from .conftest import DATA, DEVICES
from .fakes import FakeSession, item, run_until

Binder = Callable[..., DeviceBinding]
PARTS = ["alarm", "dispenser", "user"]


def test_a_binding_is_a_performer(binder: Binder, fast_profile: DeviceProfile,
                                  fast_url: Callable[[str], str]) -> None:
    assert isinstance(binder(PARTS, fast_url("none"), fast_profile), Performer)


def test_commands_complete_activities_with_reply_data_and_latency(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    binding = binder(PARTS, fast_url("none"), fast_profile)
    alarm, drawer = item("alarm_on"), item("dispense", "dispenser", slot=3)
    binding.offer(alarm)
    binding.offer(drawer)  # queued: one command on the line at a time
    run_until(binding.inbox, session, lambda: len(session.answered) == 2)
    assert session.completed == [(alarm, None), (drawer, {"slot": 3})]
    assert session.faults() == []
    exchanges = session.kinds(DEVICE_EXCHANGE)
    assert [e["command"] for e in exchanges] == ["ALARM ON", "DISPENSE 3"]
    assert all(e["latency"] > 0 for e in exchanges)
    assert len(binding.latencies) == 2
    assert binding.latency_summary().count == 2


def test_error_reply_fails_the_activity_with_the_profiles_exception(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    binding = binder(PARTS, fast_url("error:ERR+JAM"), fast_profile)
    drawer = item("dispense", "dispenser", slot=1)
    binding.offer(drawer)
    run_until(binding.inbox, session, lambda: bool(session.answered))
    ((failed, exception, message),) = session.failed
    assert (failed, exception) == (drawer, "DrawerJammed")
    assert "'ERR JAM'" in message
    # a declared error is an answer (no retry, no fallback), counted as a device-error fault
    assert session.faults() == ["device-error"]
    (fault,) = binding.faults
    assert (fault["action"], fault["exception"], fault["reply"]) == ("exception", "DrawerJammed",
                                                                     "ERR JAM")


def test_no_reply_is_a_timeout_fault_then_a_retry(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    binding = binder(PARTS, fast_url("silent:1"), fast_profile)
    alarm = item("alarm_on")
    binding.offer(alarm)
    run_until(binding.inbox, session, lambda: bool(session.answered))
    assert session.completed == [(alarm, None)]
    (fault,) = session.kinds("fault")
    assert (fault["fault"], fault["action"], fault["attempt"]) == ("timeout", "retry", 1)
    assert fault["command"] == "ALARM ON" and fault["participant"] == "alarm"
    assert "no reply to 'ALARM ON' within 300 ms" in fault["message"]


def test_timeouts_beyond_the_retries_switch_the_alarm_to_simulated(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    binding = binder(PARTS, fast_url("silent"), fast_profile)
    alarm = item("alarm_on")
    binding.offer(alarm)
    run_until(binding.inbox, session, lambda: bool(session.answered))
    assert session.completed == [(alarm, None)]  # by the simulated alarm
    assert [(f["fault"], f["action"]) for f in session.kinds("fault")] == [
        ("timeout", "retry"), ("timeout", "simulate")]
    assert binding.mode("alarm") == "simulated"
    assert binding.mode("dispenser") == "device"
    assert any("using the simulated alarm" in n["message"] for n in session.kinds(DEVICE_NOTE))
    # later alarm work goes straight to the simulation, in simulated time
    off = item("alarm_off")
    binding.offer(off)
    session.advance()
    assert session.completed[-1] == (off, None) and session.now == pytest.approx(2.0)


def test_timeouts_beyond_the_retries_abort_the_dispense_along_its_exception(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    binding = binder(PARTS, fast_url("silent"), fast_profile)
    drawer = item("dispense", "dispenser", slot=2)
    binding.offer(drawer)
    run_until(binding.inbox, session, lambda: bool(session.answered))
    ((failed, exception, message),) = session.failed
    assert (failed, exception) == (drawer, "DispenserFault")
    assert "timeout after 2 attempt(s)" in message
    assert session.faults() == ["timeout", "timeout"]


def test_garbage_is_a_named_fault_and_uses_the_fallback(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    binding = binder(PARTS, fast_url("garbage:1"), fast_profile)
    alarm = item("alarm_on")
    binding.offer(alarm)
    run_until(binding.inbox, session, lambda: bool(session.answered))
    assert session.completed == [(alarm, None)]  # the retry got a clean OK
    (fault,) = session.kinds("fault")
    assert (fault["fault"], fault["action"]) == ("garbage", "retry")
    assert "GARBLED" in fault["message"]


def _profile_with(tmp_path: Path, fallback_line: str) -> tuple[DeviceProfile, str]:
    """The fast profile with one more line in its last table, ``[fallback.dispenser]``."""
    path = tmp_path / "test_dispenser.toml"
    path.write_text((DATA / "test_dispenser.toml").read_text(encoding="utf-8")
                    + fallback_line + "\n", encoding="utf-8")
    return load_profile(path), f"emulator://{path}"


def test_a_late_reply_is_the_timed_out_commands_not_the_answer_to_the_retry(
        binder: Binder, session: FakeSession, tmp_path: Path) -> None:
    # 300 ms timeouts, replies 700 ms late, the line held up to 2 s for a late reply
    profile, url = _profile_with(tmp_path, "late_reply_ms = 2000")
    binding = binder(["dispenser"], url + "?fault=late:700", profile)
    drawer = item("dispense", "dispenser", slot=1)
    binding.offer(drawer)
    run_until(binding.inbox, session, lambda: session.faults().count("late-reply") == 2,
              timeout=15)
    faults = session.kinds("fault")
    # before: the first reply answered the retry (a 0.4 s round trip, no fault for it)
    assert [(f["fault"], f["attempt"]) for f in faults] == [
        ("timeout", 1), ("late-reply", 1), ("timeout", 2), ("late-reply", 2)]
    assert [f["action"] for f in faults if f["fault"] == "timeout"] == ["retry", "abort"]
    assert all(f["latency"] >= 0.7 and f["reply"] == "OK DISPENSED 1"
               for f in faults if f["fault"] == "late-reply")
    assert [f[1] for f in session.failed] == ["DispenserFault"]
    assert binding.latencies == [] and session.kinds(DEVICE_EXCHANGE) == []


def test_a_reply_later_than_the_hold_is_still_a_late_reply_fault(
        binder: Binder, session: FakeSession, tmp_path: Path) -> None:
    # no retry, the line held only 100 ms: the reply (900 ms) comes with nothing in flight
    profile, url = _profile_with(tmp_path, "retries = 0\nlate_reply_ms = 100")
    binding = binder(["dispenser"], url + "?fault=late:900", profile)
    binding.offer(item("dispense", "dispenser", slot=1))
    run_until(binding.inbox, session, lambda: "late-reply" in session.faults(), timeout=15)
    assert session.faults() == ["timeout", "late-reply"]
    assert [f[1] for f in session.failed] == ["DispenserFault"]
    late = session.kinds("fault")[-1]
    assert late["reply"] == "OK DISPENSED 1" and late["latency"] >= 0.9


def test_disconnect_mid_run_reconnects_and_resends(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    # emulator:// gives a fresh device on reopen, like a board that was replugged
    binding = binder(PARTS, fast_url("disconnect:1"), fast_profile)
    first, second = item("alarm_on"), item("dispense", "dispenser", slot=4)
    binding.offer(first)
    binding.offer(second)
    run_until(binding.inbox, session, lambda: len(session.answered) == 2)
    assert session.completed == [(first, None), (second, {"slot": 4})]
    (fault,) = session.kinds("fault")
    assert (fault["fault"], fault["action"], fault["command"]) == (
        "disconnected", "reconnect", "DISPENSE 4")
    assert "device disconnected" in fault["message"]
    assert any("reconnected" in n["message"] for n in session.kinds(DEVICE_NOTE))
    assert binding.requires_wall_clock


def test_unsolicited_button_line_raises_trg_1_and_completes_the_report(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    url = fast_url("none") + "&event=report@0.05"
    binding = binder(PARTS, url, fast_profile)
    report = item("report", "user")
    binding.offer(report)  # passive: nothing is sent, the button completes it
    run_until(binding.inbox, session, lambda: bool(session.triggers))
    assert session.triggers == [("trg_1", None)]
    assert session.completed == [(report, None)]


def test_withdrawn_item_is_not_completed_by_a_late_answer(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    binding = binder(PARTS, fast_url("late:100"), fast_profile)
    alarm = item("alarm_on")
    binding.offer(alarm)
    binding.withdraw(alarm, "deadline")
    run_until(binding.inbox, session, lambda: bool(session.kinds(DEVICE_EXCHANGE)))
    assert session.answered == []
    assert session.faults() == []


def test_unknown_operation_and_missing_data_fail_with_named_faults(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    binding = binder(PARTS, fast_url("none"), fast_profile)
    binding.offer(item("sing", "alarm"))
    binding.offer(item("dispense", "dispenser"))  # no slot in the data, no default
    assert session.faults() == ["unknown-operation", "missing-data"]
    assert [f[1] for f in session.failed] == ["DeviceFault", "DispenserFault"]
    assert "needs a value for {slot}" in session.failed[1][2]


def test_plain_loop_url_echo_is_reported_as_garbage(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile) -> None:
    # loop:// hands back what was written: a device that echoes instead of answering
    binding = binder(PARTS, "loop://", fast_profile)
    alarm = item("alarm_on")
    binding.offer(alarm)
    run_until(binding.inbox, session, lambda: bool(session.answered))
    assert session.faults() == ["garbage", "garbage"]
    assert "unexpected reply 'ALARM ON' to 'ALARM ON'" in session.kinds("fault")[0]["message"]
    assert session.completed == [(alarm, None)]  # simulated, after the retry failed too


def test_the_shipped_dispenser_never_sends_dispense_twice(
        binder: Binder, session: FakeSession, tmp_path: Path) -> None:
    # the shipped profile with its 3 s drawer timeout cut to 200 ms (everything else as shipped)
    text = (DEVICES / "medication_dispenser.toml").read_text(encoding="utf-8")
    assert "timeout_ms = 3000" in text
    path = tmp_path / "medication_dispenser.toml"
    path.write_text(text.replace("timeout_ms = 3000", "timeout_ms = 200"), encoding="utf-8")
    binding = binder(["alarm", "dispenser"], f"emulator://{path}?fault=silent",
                     load_profile(path))
    binding.offer(item("dispense", "dispenser", slot=1))
    binding.offer(item("alarm_on"))
    run_until(binding.inbox, session, lambda: len(session.answered) == 2, timeout=15)
    device = binding._port.device  # type: ignore[union-attr]  # the emulated board
    # the drawer: one DISPENSE, then DispenserFault; the alarm: sent, resent, simulated
    assert device.commands == 1 + 2
    assert [f[1] for f in session.failed] == ["DispenserFault"]
    assert [(f["command"], f["action"]) for f in session.kinds("fault")] == [
        ("DISPENSE 1", "abort"), ("ALARM ON", "retry"), ("ALARM ON", "simulate")]


def test_commands_queued_for_a_participant_that_goes_simulated_follow_it_at_once(
        binder: Binder, session: FakeSession, fast_profile: DeviceProfile,
        fast_url: Callable[[str], str]) -> None:
    binding = binder(PARTS, fast_url("silent"), fast_profile)
    first, second = item("alarm_on"), item("alarm_off")
    binding.offer(first)
    binding.offer(second)                  # queued behind the unanswered ALARM ON
    run_until(binding.inbox, session, lambda: bool(session.answered))
    # the same drain that gave up on the device simulated both (no wait for the line's hold)
    assert sorted(c[0].key for c in session.completed) == sorted([first.key, second.key])
    assert binding.pending() == []
