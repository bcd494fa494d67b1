"""The device panel's state, derived from the trace alone: the alarm rings from 08:00 until the
report (or the deadline), the drawer shows what it did, and a device fault lands on the
participant it concerns."""

from __future__ import annotations

import pytest

from opspec.tui.devices import DeviceBoard
from opspec.tui.session import WalkSession


def row(session: WalkSession, participant: str):
    return next(r for r in session.board.rows() if r.id == participant)


def act(session: WalkSession, activity: str, choice: str | None = None) -> None:
    """Do ``activity`` (skipping until it is offered, when it is not yet)."""
    def offered():
        return next((o for o in session.offers
                     if o.item.activity == activity and o.choice == choice), None)

    if offered() is None:
        session.skip_until_user()
    session.act(offered())


def test_device_participants_are_listed_in_spec_order_and_silent_before_eight(compiled):
    session = WalkSession(compiled)
    rows = session.board.rows()
    assert [r.id for r in rows] == ["clock", "sched", "alarm", "dispenser"]
    assert row(session, "alarm").status == "silent"
    assert not any(r.alert for r in rows)


def test_the_alarm_rings_at_eight_until_the_report_and_the_drawer_records_the_dose(compiled):
    session = WalkSession(compiled)
    session.skip_until_user()
    assert session.now == 8 * 3600
    alarm = row(session, "alarm")
    assert alarm.alert and alarm.status == "((( RINGING ))) since 08:00"
    assert "alarms=1" in alarm.detail
    assert row(session, "dispenser").status.startswith("> Wait for the user's report")
    act(session, "hear_alarm")
    session.run_to(session.now + 60)
    act(session, "walk_to_dispenser")
    act(session, "choose_button", "press_report")
    assert row(session, "alarm").status == "silent"
    dispenser = row(session, "dispenser")
    assert dispenser.status == "last: Record: taken 08:01"
    assert "outcome=taken" in dispenser.detail


def test_the_alarm_rings_again_after_each_expired_deadline(compiled):
    session = WalkSession(compiled)
    session.skip_until_user()
    session.run_to(8 * 3600 + 299)
    assert row(session, "alarm").alert
    session.run_to(8 * 3600 + 301)                # deadline expired, the alarm sounds again
    assert row(session, "alarm").status == "((( RINGING ))) since 08:05"
    assert "alarms=2" in row(session, "alarm").detail


@pytest.mark.parametrize(("data", "who"), [
    ({"fault": "timeout", "device": "medication_dispenser", "participant": "dispenser",
      "message": "dispenser: no reply to 'DISPENSE 1' within 3000 ms"}, ["dispenser"]),
    ({"fault": "disconnected", "device": "medication_dispenser",
      "message": "emulator://medication_dispenser is gone"}, ["alarm", "dispenser"]),
], ids=["fault-of-one-participant", "port-gone-hits-every-participant-of-the-device"])
def test_a_device_fault_shows_on_the_participants_it_concerns(compiled, data, who):
    session = WalkSession(compiled, device_participants={
        "medication_dispenser": ("alarm", "dispenser")})
    session.skip_until_user()
    session.sim.session.trace("fault", data)
    faulty = [r.id for r in session.board.rows() if r.status.startswith("FAULT")]
    assert faulty == who
    assert row(session, who[0]).status == f"FAULT at 08:00: {data['fault']}"
    assert data["message"] in row(session, who[0]).detail


def test_a_device_note_is_shown_beside_the_participant_without_alarming(compiled):
    board = DeviceBoard(compiled)
    session = WalkSession(compiled)
    session.sim.session.trace("device.note", {
        "device": "medication_dispenser", "message": "alarm: reconnected"})
    for event in session.events:
        board(event)
    alarm = next(r for r in board.rows() if r.id == "alarm")
    assert "note: alarm: reconnected" in alarm.detail and not alarm.alert


def test_a_note_naming_one_participant_of_a_shared_device_is_that_participant_s(compiled):
    """One device served both the alarm and the drawer (``--bind alarm=… --bind
    dispenser=…`` of one profile): its note "dispenser: application 'notify_caregiver' …"
    showed on the alarm's row too, as if the alarm had the problem."""
    session = WalkSession(compiled, device_participants={
        "medication_dispenser": ("alarm", "dispenser")})
    note = ("dispenser: application 'notify_caregiver' (notify_caregiver in notify_workflow) "
            "is not an operation of profile medication_dispenser, so it runs by itself, not "
            "on the device (operations: alarm_on, dispense)")
    session.sim.session.trace("device.note", {"device": "medication_dispenser",
                                              "message": note})
    assert f"note: {note}" in row(session, "dispenser").detail
    assert "note:" not in row(session, "alarm").detail
    # a note of the whole device (both participants named) is on both
    session.sim.session.trace("device.note", {"device": "medication_dispenser",
                                              "message": "alarm, dispenser: reconnected"})
    assert "reconnected" in row(session, "alarm").detail
    assert "reconnected" in row(session, "dispenser").detail


def test_the_summary_says_the_devices_notes_in_full(compiled):
    """The panel shows a note on one line, cut at its edge ("note: dispenser: application
    'notify_caregiver' (…" at 100 columns), and nothing else said it: the researcher never
    learnt that the caregiver's notice ran simulated, not on the device."""
    session = WalkSession(compiled, device_participants={
        "medication_dispenser": ("alarm", "dispenser")})
    note = ("dispenser: application 'notify_caregiver' (notify_caregiver in notify_workflow) "
            "is not an operation of profile medication_dispenser, so it runs by itself, not "
            "on the device (operations: alarm_on, dispense)")
    for _ in range(2):                                 # (said once)
        session.sim.session.trace("device.note", {"device": "medication_dispenser",
                                                  "message": note})
    lines = session.summary_lines(final=False)
    at = lines.index("What the bound devices said:")
    assert lines[at + 1:] == [f"  {note}"]
    assert "What the bound devices said:" not in WalkSession(compiled).summary_lines()
