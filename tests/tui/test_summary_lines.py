"""The summary's line on the answers usable for ``opspec fit`` names why the others are not,
each reason with its count after it.

It read "usable for opspec fit: 1 of 4 (not: 2x the clock ran at 60x; 1x the clock was
paused)": the counts looked like the speeds the status line shows ("1x", "60x"), and "not:"
like the omissions the same summary lists ("not: Hear the alarm")."""

from __future__ import annotations

from opspec.tui.summary import response_lines
from opspec.tui.timing import Response


def test_the_reasons_carry_their_counts_after_them():
    responses = [Response("person", 3.0, True, label="Hear the alarm"),
                 Response("person", 2.0, False, "the clock ran at 60x", label="Hear the alarm"),
                 Response("person", 4.0, False, "the clock ran at 60x", label="Take the pill"),
                 Response("person", 1.0, False, "the clock was paused", label="Take the pill")]
    assert response_lines(responses)[-1] == (
        "  usable for opspec fit: 1 of 4 (not usable: the clock ran at 60x (2); "
        "the clock was paused (1))")


def test_all_usable_says_the_clock_ran_in_real_time():
    responses = [Response("person", 3.0, True, label="Hear the alarm")]
    assert response_lines(responses)[-1] == (
        "  usable for opspec fit: 1 of 1 (the clock ran in real time)")
