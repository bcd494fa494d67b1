"""Walking the medication dispenser in the app (Textual's Pilot, headless): the alarm at
08:00, a report and the dose taken with the right latency, three ignored alarms, hand-over to
the model and back, recordings that replay to the same trace, help and quit."""

from __future__ import annotations

import json

import pytest
from walkthrough_inputs import SPEC

from opspec.tui.app import WalkthroughApp
from opspec.tui.replay import load_recording
from opspec.tui.session import WalkSession


def metric(session: WalkSession, name: str) -> dict:
    return session.sim.metrics.values()[name]


def screen_text(app: WalkthroughApp) -> str:
    return "\n".join(str(w.render()) for w in app.query("Static"))


async def start(app: WalkthroughApp, pilot) -> None:
    await pilot.press("space")          # pause: the tests drive time with keys only
    await pilot.pause()


@pytest.mark.asyncio
async def test_alarm_at_eight_then_a_report_after_90s_takes_the_dose(compiled, tmp_path):
    session = WalkSession(compiled, record=tmp_path / "walk.json")
    app = WalkthroughApp(session, title="dispenser")
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("u")                         # skip until something needs me
        assert session.now == 8 * 3600
        assert "THE DEVICE CALLS YOU" in screen_text(app)
        assert "Hear the alarm" in screen_text(app)
        await pilot.press("a")                          # I hear it
        await pilot.press("w", "w", "w")                # walking takes 90 s
        await pilot.press("a")                          # arrived
        assert [o.choice for o in session.offers] == ["press_report", "press_wrong_button"]
        await pilot.press("a")                          # the right button
        assert session.offers[0].item.activity == "take_pill"
        await pilot.press("a")
        await pilot.pause()
    assert metric(session, "doses_taken")["total"] == 1
    assert metric(session, "report_latency_s")["mean"] == pytest.approx(90.0)
    assert metric(session, "alarms")["total"] == 1


@pytest.mark.asyncio
async def test_three_ignored_alarms_end_in_a_miss_and_the_caregiver(compiled):
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        for _ in range(12):
            if session.now >= 8 * 3600 + 900:
                break
            await pilot.press("n")                      # let the device go on without me
        await pilot.pause()
        assert "notify_caregiver" in screen_text(app) or metric(
            session, "caregiver_notified")["total"] == 1
    assert metric(session, "alarms")["total"] == 3
    assert metric(session, "doses_missed")["total"] == 1
    assert metric(session, "caregiver_notified")["total"] == 1


@pytest.mark.asyncio
async def test_hand_over_to_the_model_and_take_the_lane_back(compiled, model_factory):
    session = WalkSession(compiled, model_factory=model_factory)
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await start(app, pilot)
        await pilot.press("u")
        assert session.offers
        await pilot.press("h")                          # the model takes the lane
        assert session.handed_over and not session.offers
        assert "model performs your lane" in screen_text(app)
        for _ in range(10):
            await pilot.press("n")
        await pilot.press("h")                          # and I take it back
        assert not session.handed_over
        await pilot.press("u")
        await pilot.pause()
        assert session.offers                           # the next dose asks me again
        assert session.now >= 12 * 3600
    assert metric(session, "doses_due")["total"] >= 2


@pytest.mark.asyncio
async def test_recorded_session_replays_to_the_same_trace(compiled, tmp_path):
    record = tmp_path / "walk.json"
    session = WalkSession(compiled, record=record)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("u", "a", "w", "w", "a", "b")   # the wrong button first
        await pilot.press("u", "a", "u", "a", "u", "a")
        await pilot.press("q")
    assert app.return_value == str(record)
    steps = json.loads(record.read_text(encoding="utf-8"))["steps"]
    assert any("press_wrong_button" in action for _, action in steps)
    original = [(e.time, e.kind, e.instance, e.activity) for e in session.events
                if e.kind.startswith(("activity.", "process.", "trigger."))]

    again = WalkSession(compiled, replay=load_recording(record, compiled))
    again.run_to(session.now)
    replayed = [(e.time, e.kind, e.instance, e.activity) for e in again.events
                if e.kind.startswith(("activity.", "process.", "trigger."))]
    assert replayed == original
    trace = record.with_suffix(".trace.jsonl")
    assert trace.is_file() and "walkthrough.action" in trace.read_text(encoding="utf-8")


@pytest.mark.asyncio
async def test_help_screen_lists_the_keys_and_closes(compiled, model_factory):
    app = WalkthroughApp(WalkSession(compiled, model_factory=model_factory))
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("question_mark")
        await pilot.pause()
        text = str(app.screen.query_one("#help-text").render())
        assert "pause / resume" in text and "hand your lane" in text and "ctrl+c" in text
        assert app.session.paused                      # the clock waits while I read
        await pilot.press("escape")
        await pilot.pause()
        assert not app.screen.query("#help-text")
        assert not app.session.paused                  # and runs again as it did


@pytest.mark.asyncio
async def test_quitting_returns_the_recording_path_and_keeps_what_was_done(compiled, tmp_path):
    record = tmp_path / "r.json"
    session = WalkSession(compiled, record=record)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("u", "a")
        # the recording is on disk before quitting: a crash now would lose nothing
        assert "complete hear_alarm" in record.read_text(encoding="utf-8")
        await pilot.press("q")
    assert app.return_value == str(record)


def test_broken_spec_opens_nothing_and_prints_the_diagnostics(tmp_path, capsys):
    from opspec.cli import main

    broken = tmp_path / "broken.xpdl"
    broken.write_text(SPEC.read_text(encoding="utf-8").replace("</Package>", ""),
                      encoding="utf-8")
    assert main(["walkthrough", str(broken)]) == 1
    assert f"{broken}:" in capsys.readouterr().err


@pytest.mark.asyncio
async def test_ctrl_c_quits_cleanly_with_the_recording_path(compiled, tmp_path):
    record = tmp_path / "c.json"
    app = WalkthroughApp(WalkSession(compiled, record=record))
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("ctrl+c")
    assert app.return_value == str(record)
    assert record.is_file()


@pytest.mark.asyncio
async def test_a_device_fault_is_shown_on_its_participant(compiled):
    session = WalkSession(compiled, device_participants={
        "medication_dispenser": ("alarm", "dispenser")})
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("u")
        assert "((( RINGING )))" in screen_text(app)
        session.sim.session.trace("fault", {
            "fault": "disconnected", "device": "medication_dispenser",
            "message": "the board is gone"})
        await pilot.press("w")
        text = screen_text(app)
        assert "(x) alarm: FAULT at 08:00: disconnected" in text
        assert "(x) dispenser: FAULT" in text


async def until(pilot, condition, what: str, limit: int = 300) -> None:
    """Let the app run (a device answers in wall time) until ``condition()`` holds."""
    for _ in range(limit):
        if condition():
            return
        await pilot.pause(0.05)
    raise AssertionError(f"never happened: {what}")


@pytest.mark.asyncio
async def test_a_bound_device_that_drops_the_line_shows_a_fault_and_the_walk_goes_on(compiled):
    from opspec.bindings.attach import attach_devices

    url = "emulator://medication_dispenser?fault=disconnect:1"
    with attach_devices([f"alarm={url}", f"dispenser={url}"], SPEC.parents[1] / "devices") as d:
        session = WalkSession(compiled, performers=d.performers, wall_devices=True,
                              device_participants={"medication_dispenser": ("alarm",
                                                                            "dispenser")})
        d.install(session.sim)
        app = WalkthroughApp(session)
        async with app.run_test(size=(80, 24)) as pilot:
            await start(app, pilot)
            await pilot.press("u")             # the skip waits for the board's answer
            await until(pilot, lambda: session.offers, "the alarm reached the person")
            assert session.now == 8 * 3600     # not skipped past the dose
            await pilot.press("a", "w", "a", "a")   # hear, walk, press report: dispense
            await until(pilot, lambda: any(r.status.startswith("FAULT")
                                           for r in session.board.rows()), "a fault")
            await until(pilot, lambda: not session.device_work, "the fallback answered")
            await pilot.press("w")
            assert "(x) " in screen_text(app) and "FAULT at 08:0" in screen_text(app)
            await pilot.press("a", "u")         # take the pill; on to the next dose
            await until(pilot, lambda: bool(session.offers) and session.now > 9 * 3600,
                        "the next dose after the fault")


def test_a_walkthrough_trace_fits_a_user_model(compiled, tmp_path, capsys):
    from opspec.cli import main

    record = tmp_path / "walk.json"
    session = WalkSession(compiled, record=record)
    for _dose in range(3):
        for activity in ("hear_alarm", "walk_to_dispenser", "choose_button", "take_pill"):
            if not any(o.item.activity == activity for o in session.offers):
                session.skip_until_user()
            session.run_to(session.now + 45)
            session.act(next(o for o in session.offers if o.item.activity == activity))
    session.close()
    assert json.loads(record.read_text(encoding="utf-8"))["steps"][0] == [
        "at 28845.0", "complete hear_alarm #4"]
    actions = [json.loads(line) for line in
               record.with_suffix(".trace.jsonl").read_text(encoding="utf-8").splitlines()
               if "walkthrough.action" in line]
    assert len(actions) == 12 and all(a["data"]["wall"] > 0 for a in actions)
    fitted = tmp_path / "fitted.toml"
    assert main(["fit", str(record.with_suffix(".trace.jsonl")), "-o", str(fitted)]) == 0
    text = fitted.read_text(encoding="utf-8")
    assert "[activities.walk_to_dispenser]" in text and 'intended = "press_report"' in text


@pytest.mark.asyncio
async def test_replaying_a_recording_in_the_app_performs_it_by_itself(compiled, tmp_path):
    record = tmp_path / "walk.json"
    record.write_text('{"otherwise": "wait", "steps": [["at 28830.0", "complete hear_alarm"],'
                      ' ["at 28890.0", "complete walk_to_dispenser"],'
                      ' ["at 28890.0", "choose press_report"],'
                      ' ["at 28900.0", "complete take_pill"]]}', encoding="utf-8")
    session = WalkSession(compiled, replay=load_recording(record, compiled))
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        assert "replaying the recording" in screen_text(app)
        for _ in range(8):
            await pilot.press("n")
        await pilot.press("w", "w", "w")
        assert not session.offers                       # nothing is offered to the person
    assert metric(session, "doses_taken")["total"] == 1
    assert metric(session, "report_latency_s")["mean"] == pytest.approx(90.0)


@pytest.mark.asyncio
async def test_an_offer_is_done_by_clicking_it_and_the_timeline_filters_lanes(compiled):
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("u")
        assert await pilot.click(".offer")
        await pilot.pause()
        assert session.offers[0].item.activity == "walk_to_dispenser"
        timeline = app.query_one("#timeline")
        assert "user    you: complete hear_alarm" in str(timeline.render())
        await pilot.press("l")                          # device only
        shown = str(timeline.render())
        assert "showing: device" in shown and "device  trigger trg_2 raised" in shown
        assert " user " not in shown
        await pilot.press("l")                          # user only
        shown = str(timeline.render())
        assert "showing: user" in shown and "you: complete hear_alarm" in shown
        assert "hear_alarm completed" in shown and " device " not in shown


@pytest.mark.asyncio
async def test_while_the_model_has_the_lane_skipping_stops_at_the_next_call(compiled,
                                                                          model_factory):
    session = WalkSession(compiled, model_factory=model_factory)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("h", "u")                     # the model performs; skip
        assert session.now == 8 * 3600 and session.calls == 1
        assert "model performs your lane" in screen_text(app)
        await pilot.press("n", "n", "n", "u")
        assert 8 * 3600 < session.now <= 12 * 3600


@pytest.mark.asyncio
async def test_q_in_the_help_screen_quits(compiled, tmp_path):
    record = tmp_path / "h.json"
    app = WalkthroughApp(WalkSession(compiled, record=record))
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("question_mark")
        await pilot.pause()
        assert "ctrl+q" in str(app.screen.query_one("#help-text").render())
        await pilot.press("q")
        await pilot.pause()
    assert app.return_value == str(record)


@pytest.mark.asyncio
async def test_a_replay_says_the_recording_performs_and_has_nothing_to_hand_over(
        compiled, tmp_path, model_factory):
    record = tmp_path / "walk.json"
    record.write_text('{"otherwise": "wait", "steps": [["at 28830.0", "complete hear_alarm"]]}',
                      encoding="utf-8")
    session = WalkSession(compiled, replay=load_recording(record, compiled),
                          model_factory=model_factory)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("h")
        assert not session.handed_over
        text = screen_text(app)
        assert "the recording performs your lane" in text
        assert "model is performing" not in text and "press u to skip" not in text


@pytest.mark.asyncio
async def test_with_the_lane_handed_over_the_panel_says_only_that(compiled, model_factory):
    session = WalkSession(compiled, model_factory=model_factory)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("h")
        text = screen_text(app)
        assert "The user model is performing. Press h to take over." in text
        assert "nothing to do now" not in text


@pytest.mark.asyncio
async def test_a_fault_in_the_timeline_is_in_the_device_lane(compiled):
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        session.sim.session.trace("fault", {"fault": "disconnected",
                                            "device": "medication_dispenser"})
        await pilot.press("l")                         # device lane only
        assert "device  FAULT medication_dispenser" in str(app.query_one("#timeline").render())


@pytest.mark.asyncio
async def test_a_call_with_nothing_to_do_says_so(compiled):
    """After ``x`` (the person lets the alarm pass) the alarm rings on for five minutes, in
    real time: the panel showed "THE DEVICE CALLS YOU" and no action, nothing saying that
    nothing was asked of the person or how to move on."""
    session = WalkSession(compiled)
    app = WalkthroughApp(session, title="dispenser")
    async with app.run_test(size=(80, 24)) as pilot:
        await start(app, pilot)
        await pilot.press("u")                      # 08:00: the alarm
        await pilot.pause()
        call = str(app.query_one("#call").render())
        assert "THE DEVICE CALLS YOU" in call and "nothing to do now" not in call
        await pilot.press("x")                      # let "Hear the alarm" pass
        await pilot.pause()
        assert session.calling and not session.offers
        call = str(app.query_one("#call").render())
        assert "THE DEVICE CALLS YOU" in call
        assert "(nothing to do now: press u to skip until something needs you)" in call
