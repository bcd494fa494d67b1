"""What the walkthrough says about its end is true for the session shown.

- The help (``?``) said "quit (the recording is kept)" and "an omission, recorded" in every
  session: also in a replay, which records nothing, and with ``--no-record``.
- The summary of a ``--no-record`` session counted the person's answers "usable for opspec
  fit": there is no trace for opspec fit to read.
- The replay commands printed after a session with bound devices did not say that they
  simulate those devices: the replay's numbers are not the session's (a dose the bound
  device was still dispensing at 12:00 is not due in the replay).
"""

from __future__ import annotations

import pytest
from rich.text import Text

from opspec.tui.app import WalkthroughApp
from opspec.tui.replay import load_recording
from opspec.tui.session import WalkSession

UNTIL = 9 * 3600.0


async def _help(session: WalkSession) -> str:
    """The help screen's text, as the person reads it."""
    session.paused = True
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 50)) as pilot:
        await pilot.press("question_mark")
        await pilot.pause()
        widget = app.screen.query_one("#help-text")
        text = str(widget.render())
        inner = widget.content_region
        # each of its lines on one line of the screen (tests/tui/test_help_fits.py)
        assert inner.height == len(text.splitlines())
        assert max(Text(line).cell_len for line in text.splitlines()) <= inner.width
        await pilot.press("escape")
        await pilot.press("q")
    return text


def _line(text: str, start: str) -> str:
    return next(line.strip() for line in text.splitlines() if line.strip().startswith(start))


@pytest.mark.asyncio
async def test_the_help_says_what_quitting_keeps_in_this_session(compiled, tmp_path):
    recorded = await _help(WalkSession(compiled, record=tmp_path / "kept.json"))
    assert _line(recorded, "q, ctrl+c") == "q, ctrl+c, ctrl+q quit (the recording is kept)"
    assert _line(recorded, "x") == "x       do not do the first action (an omission, recorded)"

    unrecorded = await _help(WalkSession(compiled))                  # --no-record
    assert _line(unrecorded, "q, ctrl+c") == "q, ctrl+c, ctrl+q quit (nothing is recorded)"
    assert _line(unrecorded, "x") == "x       do not do the first action (an omission)"

    script = tmp_path / "walk.json"
    script.write_text('{"otherwise": "wait", "steps": [["at 28830.0", "complete hear_alarm"]]}',
                      encoding="utf-8")
    replay = await _help(WalkSession(compiled, replay=load_recording(script, compiled)))
    assert _line(replay, "q, ctrl+c") == "q, ctrl+c, ctrl+q quit (a replay records nothing)"
    # (nothing is answered in a replay: no x at all, tests/tui/test_help_lists_what_works.py)
    assert "an omission" not in replay


def _answer_the_first_alarm(session: WalkSession) -> WalkSession:
    session.skip_until_user()
    session.act(next(o for o in session.offers if o.item.activity == "hear_alarm"))
    return session


def test_a_session_not_recorded_does_not_offer_its_answers_to_opspec_fit(compiled, tmp_path):
    unrecorded = _answer_the_first_alarm(WalkSession(compiled, until=UNTIL))
    lines = unrecorded.summary_lines()
    assert not any("usable for opspec fit" in line for line in lines)
    assert "  (nothing was recorded: opspec fit has no trace of them)" in lines
    # a recorded one still says how many are usable
    recorded = _answer_the_first_alarm(WalkSession(compiled, until=UNTIL,
                                                   record=tmp_path / "kept.json"))
    assert any(line.startswith("  usable for opspec fit: 1 of 1")
               for line in recorded.summary_lines())
    recorded.close()


def test_the_replay_commands_of_a_session_with_bound_devices_say_they_simulate_them(
        compiled, tmp_path):
    bound = WalkSession(compiled, until=UNTIL, record=tmp_path / "bound.json",
                        device_participants={"medication_dispenser": ("alarm", "dispenser")})
    bound.skip_until_user()     # (quit before the clock moved, nothing is replayed)
    lines = bound.summary_lines()
    bound.close()
    after = lines[next(i for i, line in enumerate(lines) if line.startswith("           or:"))
                  + 1:]
    assert after == [("Both replays simulate alarm, dispenser, performed here by a bound "
                      "device: their numbers may differ from this session's.")]
    # without a bound device, the replay commands end the summary as before
    plain = WalkSession(compiled, until=UNTIL, record=tmp_path / "plain.json")
    plain.skip_until_user()
    assert plain.summary_lines()[-1].startswith("           or: opspec run")
    plain.close()
