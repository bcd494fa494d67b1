"""What the person chose not to do (``x``) has no response time. The summary listed
``not: Hear the alarm  median 2.1 s, max 2.1 s, n 1`` among the response times, and counted
it in "usable for opspec fit: 2 of 2", though ``opspec fit`` fits no duration from an omission
(it counts it as one, timed or not). It is now listed apart, by action, without a time."""

from __future__ import annotations

from walkthrough_inputs import SPEC
from opspec.tui.session import WalkSession


def section(lines: list[str]) -> list[str]:
    start = lines.index("Your response times (wall clock, from the offer to your key):")
    end = lines.index("", start) if "" in lines[start:] else len(lines)
    return lines[start + 1:end]


def test_a_skipped_action_is_counted_apart_without_a_time(compiled, tmp_path):
    session = WalkSession(compiled, record=tmp_path / "x.json", spec_path=str(SPEC))
    session.skip_until_user()                          # 08:00: Hear the alarm
    session.ignore(session.offers[0])                  # x
    session.run_to(session.now + 400)
    session.skip_until_user()                          # the re-alarm: Hear the alarm again
    session.act(session.offers[0])
    session.close()
    shown = section(session.summary_lines())
    assert shown[0].startswith("  Hear the alarm  median ") and shown[0].endswith(", n 1")
    assert shown[1] == "  not done (x, no response time): Hear the alarm (1)"
    assert shown[2].startswith("  usable for opspec fit: 1 of 1")
    assert not any("not: " in line for line in shown)


def test_only_skipped_actions_answered_nothing(compiled):
    session = WalkSession(compiled, spec_path=str(SPEC))      # --no-record
    session.skip_until_user()
    session.ignore(session.offers[0])
    assert section(session.summary_lines()) == [
        "  (you answered nothing)", "  not done (x, no response time): Hear the alarm (1)"]
