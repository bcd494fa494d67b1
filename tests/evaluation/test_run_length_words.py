"""How an evaluation's run length is written for people (the report's tables, findings and
captions: ``opspec.evaluation.plan.span``): whole and simple numbers of days as days, and a
length that no number of days with two decimals writes exactly as :func:`opspec.clock.span`
writes it, to the millisecond, never rounded to four significant digits (0.123456 days were
"2.963 h", 9 seconds short)."""

from __future__ import annotations

import pytest

from opspec.clock import parse_duration
from opspec.evaluation.plan import DAY, span


@pytest.mark.parametrize(("days", "text"), [
    (30.0, "30 days"), (1.0, "1 day"), (1.5, "1.5 days"), (2.25, "2.25 days"),
    (0.5, "12 h"), (0.25, "6 h"), (1 / 24, "1 h"), (0.3, "7.2 h"), (0.0001, "8.64 s"),
    (0.123456, "2 h 57 min 46.598 s"), (1.23456789, "29 h 37 min 46.666 s")])
def test_a_run_length_is_written_as_it_is(days: float, text: str) -> None:
    assert span(days) == text


@pytest.mark.parametrize("days", [0.123456, 1.23456789, 0.7777777, 0.0123, 3.14159])
def test_what_is_written_reads_back_to_the_millisecond(days: float) -> None:
    text = span(days)
    seconds = float(text.split()[0]) * DAY if text.endswith(("day", "days")) else (
        parse_duration(text))
    assert seconds == pytest.approx(days * DAY, abs=0.0005)
