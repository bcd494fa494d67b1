"""What the person is offered: superseded and ended offers go, the newest alarm is the one
to answer, more offers than keys are counted, choices show the spec's names; the banner and
the bell follow the alarm; taking the lane back from the model returns its pending work."""

from __future__ import annotations

import pytest

from opspec.engine.performers import WorkItem
from opspec.tui.app import OFFER_KEYS, WalkthroughApp
from opspec.tui.session import WalkSession


def model_actions(session: WalkSession) -> list[str]:
    return [e.data["action"] for e in session.events
            if e.kind == "walkthrough.action" and e.data["by"] == "model"]


def ignore_three_alarms(session: WalkSession) -> None:
    session.skip_until_user()                      # 08:00
    while session.now < 8 * 3600 + 900:            # 08:05 and 08:10 alarms, 08:15 miss
        session.skip_to_next_event()


def test_ignored_alarms_leave_one_offer_the_newest(compiled):
    session = WalkSession(compiled)
    ignore_three_alarms(session)
    assert [(o.label, o.item.instance) for o in session.offers] == [("Hear the alarm", 6)]
    assert session.lapsed == 2


def test_skipping_passes_the_offers_already_shown(compiled):
    session = WalkSession(compiled)
    ignore_three_alarms(session)
    session.skip_until_user()                      # not stuck at 08:15 on the old offer
    assert session.now == 12 * 3600 and not session.skipping
    assert [o.label for o in session.offers] == ["Hear the alarm"]
    assert session.offers[0].item.instance > 6


def test_the_banner_follows_the_alarm_not_the_user_workflows(compiled):
    session = WalkSession(compiled)
    session.skip_until_user()
    assert session.calling                         # ringing, offer waiting
    ignore_three_alarms(session)
    assert not session.board.ringing and session.offers
    assert not session.calling                     # silent: the device no longer calls
    session.skip_until_user()
    assert session.calling                         # 12:00


def fake_item(key: int, activity: str, label: str, process: str = "p") -> WorkItem:
    return WorkItem(key, process, 100 + key, activity, label, None, "user", 0.0)


@pytest.mark.asyncio
async def test_more_offers_than_keys_say_how_many_more_and_twins_show_their_instance(
        compiled):
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space")
        extra = len(OFFER_KEYS) + 2                  # every free letter, and 3 more
        for key in range(extra):
            session._offered(fake_item(key, f"act{key}", f"Do {key}"))
        session._offered(fake_item(extra, "same", "Do 0", process="q"))  # a twin of "Do 0"
        app.refresh_views()
        await pilot.pause()
        shown = [str(w.render()) for w in app.query("#offers Static")]
        assert shown[0] == "[a] Do 0 #100" and shown[5] == "[f] Do 5"
        # after f the letters go on past those the controls use (h l n q s u w x)
        assert shown[6] == "[g] Do 6" and shown[7] == "[i] Do 7"
        assert shown[-1] == "(+3 more: x passes on the first)"


def test_every_offer_shown_is_one_key_away_and_no_offer_key_is_a_control():
    controls = {key for b in WalkthroughApp.BINDINGS if not b.action.startswith("offer(")
                for key in b.key.split(",")}
    keys = [b.key for b in WalkthroughApp.BINDINGS if b.action.startswith("offer(")]
    assert keys == list(OFFER_KEYS) and not set(keys) & controls
    assert len(OFFER_KEYS) == 18                    # a..z less the eight control letters


@pytest.mark.asyncio
async def test_choices_show_the_specs_names(compiled):
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space", "u", "a", "w", "w", "w", "a")
        assert [o.label for o in session.offers] == ['Press "report"', "Press the wrong button"]
        assert [o.choice for o in session.offers] == ["press_report", "press_wrong_button"]
        shown = [str(w.render()) for w in app.query("#offers Static")]
        assert shown == ['[a] Press "report"', "[b] Press the wrong button"]


@pytest.mark.asyncio
async def test_the_bell_rings_at_every_alarm(compiled):
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    bells = []
    app.bell = lambda: bells.append(session.now)   # type: ignore[method-assign]
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space", "u")
        while session.now < 8 * 3600 + 900:
            await pilot.press("n")
    assert bells == [28800.0, 29100.0, 29400.0]    # 08:00, 08:05, 08:10


def test_taking_the_lane_back_returns_the_models_work_and_stops_it(compiled, model_factory):
    session = WalkSession(compiled, model_factory=model_factory)
    session.skip_until_user()
    assert session.hand_over()
    for _ in range(20):                            # the model hears the alarm and walks
        if any(i.activity == "walk_to_dispenser" for i in session.lane_user.items.values()):
            break
        session.skip_to_next_event()
    else:
        raise AssertionError("the model never held 'walk to the dispenser'")
    done = model_actions(session)
    session.take_back()
    assert not session.handed_over
    assert [o.item.activity for o in session.offers] == ["walk_to_dispenser"]
    session.run_to(session.now + 120)              # the model's walk would end in here
    assert model_actions(session) == done          # it does nothing more
    session.act(session.offers[0])                 # the person walks on
    assert [o.choice for o in session.offers] == ["press_report", "press_wrong_button"]
