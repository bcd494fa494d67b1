"""Durations, times of day and rates read into seconds (or events per second)."""

from __future__ import annotations

import pytest

from opspec.errors import SourceLocation, SpecError
from opspec.model.expressions import Binary, Literal, Name
from opspec.xpdl.conditions import ConditionSyntaxError
from opspec.clock import parse_duration, parse_rate, parse_time_of_day
from opspec.xpdl.durations import parse_duration_expression

DURATIONS = [
    ("PT5M", 300.0), ("P1D", 86400.0), ("PT0.5S", 0.5), ("P1DT2H", 93600.0),
    ("pt1h30m", 5400.0), ("P2W", 14 * 86400.0), ("PT1,5H", 5400.0), ("P1Y", 365 * 86400.0),
    ("P1M", 30 * 86400.0), ("300", 300.0), ("0.5", 0.5), ("1e3", 1000.0), ("300 s", 300.0),
    ("5 min", 300.0), ("100ms", 0.1), ("2h", 7200.0), ("1.5 days", 129600.0),
    ("3 Days", 3 * 86400.0), ("1h 30min", 5400.0), ("250us", 0.00025), ("2 weeks", 14 * 86400.0),
    ("01:30", 5400.0), ("00:05:00", 300.0), ("00:00:01.5", 1.5), ("  PT5M \n", 300.0),
]


@pytest.mark.parametrize(("text", "seconds"), DURATIONS, ids=[d[0].strip() for d in DURATIONS])
def test_durations_read_into_seconds(text: str, seconds: float) -> None:
    assert parse_duration(text) == pytest.approx(seconds)


BAD_DURATIONS = [
    ("", "it is empty"), ("P", "not a duration"), ("PT", "not a duration"),
    ("P1DT", "not a duration"), ("abc", "not a duration"), ("5 parsecs", "not a duration"),
    ("-5", "cannot be negative"), ("1e999", "too large"), ("5 min 3", "not a duration"),
    ("10:75", "not a duration"),
]


@pytest.mark.parametrize(("text", "fragment"), BAD_DURATIONS, ids=[b[0] or "empty" for b in BAD_DURATIONS])
def test_unreadable_durations_are_spec_errors_with_a_hint(text: str, fragment: str) -> None:
    with pytest.raises(SpecError, match=fragment) as caught:
        parse_duration(text)
    assert "PT5M" in caught.value.hint


def test_duration_error_names_the_file_and_line() -> None:
    with pytest.raises(SpecError, match=r"^pump\.xpdl:9: cannot read duration 'soon'"):
        parse_duration("soon", location=SourceLocation("pump.xpdl", 9))


TIMES = [("08:00", 28800.0), ("8:00", 28800.0), ("17:30:15", 63015.0), ("00:00", 0.0),
         ("24:00", 86400.0), ("8:00 pm", 72000.0), ("12:00 am", 0.0), ("12:30pm", 45000.0)]


@pytest.mark.parametrize(("text", "seconds"), TIMES, ids=[t[0] for t in TIMES])
def test_times_of_day_read_into_seconds_since_midnight(text: str, seconds: float) -> None:
    assert parse_time_of_day(text) == seconds


@pytest.mark.parametrize("text", ["25:00", "8", "08:60", "13:00 pm", "noon"])
def test_impossible_times_of_day_are_spec_errors(text: str) -> None:
    with pytest.raises(SpecError, match="cannot read time of day"):
        parse_time_of_day(text)


RATES = [("10Hz", 10.0), ("10 hz", 10.0), ("2.5kHz", 2500.0), ("10/s", 10.0), ("10", 10.0),
         ("6/min", 0.1), ("6 per minute", 0.1), ("3600/h", 1.0), ("2/day", 2 / 86400)]


@pytest.mark.parametrize(("text", "rate"), RATES, ids=[r[0] for r in RATES])
def test_rates_read_into_events_per_second(text: str, rate: float) -> None:
    assert parse_rate(text) == pytest.approx(rate)


@pytest.mark.parametrize("text", ["0", "-1Hz", "fast", "Hz", "1e999"])
def test_impossible_rates_are_spec_errors(text: str) -> None:
    with pytest.raises(SpecError, match="cannot read rate"):
        parse_rate(text)


def test_plain_deadline_durations_become_literal_seconds() -> None:
    assert parse_duration_expression("PT5M") == Literal(300.0)
    assert parse_duration_expression("300") == Literal(300.0)
    assert isinstance(parse_duration_expression("300").value, float)  # type: ignore[attr-defined]


def test_deadline_durations_over_data_fields_become_expressions() -> None:
    assert parse_duration_expression("timeout * 60") == Binary("*", Name(("timeout",)), Literal(60))


def test_unreadable_deadline_expression_says_duration() -> None:
    with pytest.raises(ConditionSyntaxError, match=r"cannot read duration 'timeout \*' at column 10"):
        parse_duration_expression("timeout *")


def test_negative_deadline_duration_is_refused() -> None:
    with pytest.raises(SpecError, match="cannot be negative"):
        parse_duration_expression("-5")


def test_empty_deadline_duration_is_refused() -> None:
    with pytest.raises(SpecError, match="it is empty"):
        parse_duration_expression("  ")
