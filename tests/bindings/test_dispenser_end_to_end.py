"""The shipped dispenser spec and profile, end to end, against an independent board process
(tests/bindings/dispenser_board.py, which imports nothing from opspec) over a real
pseudo-terminal pair made by socat: a clean run, garbage, late replies, a jammed drawer, an
empty slot, an unplugged cable and a press before any alarm. In every case each due dose
ends as taken or missed (taken + missed = due), and a device fault reaches the caregiver.

Each run goes from 00:00 to 11:40 simulated at 5000x: one dose, at 08:00, slot 1. The runs
are made side by side, each with a board and a pty pair of its own (board_runs.py, the
``board_runs`` fixture): they wait on the wall clock, so together they take the time of one.
"""

from __future__ import annotations

import shutil
from typing import Any

import pytest

from .board_runs import BoardRun
from .conftest import needs_pty

pytestmark = [
    needs_pty,
    pytest.mark.skipif(shutil.which("socat") is None,
                       reason="needs socat for the pty pair: run scripts/system-deps.sh"),
]


def unpack(run: BoardRun) -> tuple[dict[str, Any], list[dict[str, Any]], list[str]]:
    """The run's JSON document, trace and board log."""
    return run.doc, run.events, run.log


def totals(doc: dict[str, Any]) -> dict[str, int]:
    return {name: doc["metrics"][name]["total"] for name in
            ("doses_due", "doses_taken", "doses_missed", "caregiver_notified")}


def device(doc: dict[str, Any]) -> dict[str, Any]:
    return doc["devices"]["alarm, dispenser"]


def fault_kinds(doc: dict[str, Any]) -> list[str]:
    return [f["fault"] for f in device(doc)["faults"]]


def completed(events: list[dict[str, Any]], activity: str) -> list[dict[str, Any]]:
    return [e for e in events if e.get("kind") == "activity.completed"
            and e.get("activity") == activity]


def assert_every_dose_decided(doc: dict[str, Any], events: list[dict[str, Any]]) -> None:
    counts = totals(doc)
    assert counts["doses_due"] == 1
    assert counts["doses_taken"] + counts["doses_missed"] == counts["doses_due"], counts
    ended = [e for e in events if e.get("kind") == "process.completed"
             and e.get("process") == "notify_workflow"]
    assert len(ended) == counts["doses_due"], "a notify instance did not end"
    assert not [e for e in events if e.get("kind") == "process.aborted"
                and e.get("process") != "user_workflow"]
    # --no-user: the board's button reports, nobody performs the user lane, whose instances
    # are the only ones left waiting (reported as deadlocks, hence exit status 1)
    assert all("'user_workflow'" in d for d in doc.get("deadlocks") or []), doc["deadlocks"]


def test_clean_board_the_morning_dose_is_taken_from_slot_1(board_runs):
    doc, events, log = unpack(board_runs["clean"])
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_taken"] == 1
    assert "RX DISPENSE 1" in log                   # the morning dose's slot, not "DISPENSE 1"
    assert fault_kinds(doc) == []                   # by default for every dose
    assert device(doc)["mode"] == {"alarm": "device", "dispenser": "device"}


def test_garbage_is_a_fault_then_a_retry_and_the_dose_is_taken(board_runs):
    # the garbled answer ends its attempt at the 500 ms timeout (a reply may follow noise),
    # over an hour simulated at 5000x: the press 20 ms after the first ALARM ON is kept
    # for the dose's wait (as in the late-reply test below)
    doc, events, log = unpack(board_runs["garbage"])     # --garbage 1 --noise, KEEP_A_DAY
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_taken"] == 1
    kinds = fault_kinds(doc)
    assert "garbage" in kinds and "unexpected-line" in kinds
    assert log.count("RX ALARM ON") == 2            # the garbled answer was retried once
    assert device(doc)["mode"]["alarm"] == "device"


def test_a_late_reply_and_a_press_during_the_retry_the_press_is_not_lost(board_runs):
    # ALARM ON's reply comes 800 ms late (timeout 500 ms): timeout, late-reply, retry. The
    # user presses 20 ms after the first ALARM ON, while nothing waits for the report yet:
    # the message is kept and the dose's wait catches it. (At this test's 5000x speed the
    # retry's wall-clock second is over an hour of simulated time: longer than the default
    # message_ttl of 60 s, so the test keeps messages for a day.)
    doc, events, log = unpack(board_runs["late-reply"])  # --late-ms 800 --late-count 1
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_taken"] == 1
    kinds = fault_kinds(doc)
    assert kinds[:2] == ["timeout", "late-reply"], kinds
    assert [e for e in events if e.get("kind") == "trigger.kept"]
    assert log.count("RX ALARM ON") == 2
    assert device(doc)["mode"]["alarm"] == "device"  # one failed attempt does not switch


def test_a_jammed_drawer_is_a_missed_dose_and_the_caregiver_is_told(board_runs):
    doc, events, log = unpack(board_runs["jam"])
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_missed"] == 1
    assert totals(doc)["caregiver_notified"] == 1
    assert completed(events, "drawer_jammed")
    assert [f for f in device(doc)["faults"] if f["fault"] == "device-error"]
    assert "RX DISPENSE 1" in log


def test_an_empty_slot_is_a_missed_dose_and_the_caregiver_is_told(board_runs):
    doc, events, _ = unpack(board_runs["empty"])
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_missed"] == totals(doc)["caregiver_notified"] == 1
    assert completed(events, "drawer_empty")
    assert "device-error" in fault_kinds(doc)


def test_an_unplugged_cable_at_dispense_is_a_missed_dose_and_the_caregiver_is_told(
        board_runs):
    doc, events, log = unpack(board_runs["unplug"])
    assert "UNPLUG" in log
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_missed"] == totals(doc)["caregiver_notified"] == 1
    assert completed(events, "dispense_failed")
    kinds = fault_kinds(doc)
    assert "disconnected" in kinds and "reconnect-failed" in kinds
    assert device(doc)["mode"] == {"alarm": "simulated", "dispenser": "aborted"}


def test_a_press_long_before_the_alarm_is_lost_and_does_not_report_the_next_dose(
        board_runs):
    # documented in devices/README.md: the board's presses are plain messages; one with
    # nothing waiting is kept for message_ttl (60 s) and then lost, so a press hours before
    # the 08:00 alarm does not count as taking that dose (here nobody presses again: missed)
    # (--press-at-ms 3500 --no-press: the board starts once the run has opened the port,
    # so the press comes 1.5 s into the run after the 2 s settle: about 02:05 simulated)
    doc, events, _ = unpack(board_runs["early-press"])
    assert_every_dose_decided(doc, events)
    assert totals(doc)["doses_taken"] == 0 and totals(doc)["doses_missed"] == 1
    kept = [e for e in events if e.get("kind") == "trigger.kept"]
    lost = [e for e in events if e.get("kind") == "trigger.lost"]
    assert kept and kept[0]["time"] < 8 * 3600
    assert lost and "message_ttl" in lost[0]["data"]["reason"]
