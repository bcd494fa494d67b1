"""One duration grammar and one time-of-day parser behind every front door (issue 18).

Every place a person writes a length of time — an XPDL/SISARL spec, a monitor, a script step,
a scenario file, an expectation, the CLI's ``--until`` — accepts the same spellings and refuses
the same ones with the same message (each door may say where, and put its context in front).
Likewise for times of day: SISARL timers, user-model routines, script ``at`` steps.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import pytest

from opspec import clock
from opspec.errors import OpspecError
from opspec.model.expressions import Name
from opspec.properties.language import MinGap
from opspec.properties.monitors import parse_monitor
from opspec.testing.expectations import parse_expectation
from opspec.testing.scenario import _until
from opspec.testing.script import parse_script
from opspec.usermodels.routine import Window
from opspec.xpdl import parse_bytes
from opspec.xpdl.durations import parse_duration_expression, parse_time_date

HEAD = ('<?xml version="1.0"?>\n<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" '
        'xmlns:opspec="urn:opspec:sisarl:1" Id="pkg">')


def _spec(process_ea: str) -> str:
    return (f'{HEAD}<WorkflowProcesses><WorkflowProcess Id="p"><Activities><Activity Id="a"/>'
            f"</Activities><ExtendedAttributes>\n{process_ea}</ExtendedAttributes>"
            "</WorkflowProcess></WorkflowProcesses></Package>")


def _directives(name: str, value: str) -> object:
    """A process directive read from a spec; its first error raised as it is reported."""
    result = parse_bytes(_spec(f'<ExtendedAttribute Name="opspec:{name}" Value="{value}"/>')
                         .encode(), path="s.xpdl")
    if result.errors:
        error = result.errors[0]
        assert error.location.path == "s.xpdl" and error.location.line == 3   # file:line
        raise OpspecError(error.message, location=error.location, hint=error.hint)
    assert result.package is not None
    return result.package.processes[0].directives


def _deadline(text: str) -> float:
    expression = parse_duration_expression(text)
    value = getattr(expression, "value", None)
    assert isinstance(value, float), f"{text!r} was read as an expression, not a duration"
    return value


def _monitor(text: str) -> float:
    monitor = parse_monitor(f"min_gap dispense {text}")
    assert isinstance(monitor, MinGap)
    return monitor.seconds


def _expectation(text: str) -> float:
    from opspec.testing.expectations import _duration

    expectation = parse_expectation(f"never activity dispense twice within {text}")
    return _duration(expectation.groups["gap"])


def _cli_until(text: str) -> float:
    from opspec.run_rules import parse_until

    return parse_until(text, name="--until")


DURATION_DOORS: dict[str, Callable[[str], float]] = {
    "clock": clock.parse_duration,
    "xpdl-deadline": _deadline,
    "sisarl-period": lambda text: float(_directives("Period", text).period),
    "monitor": _monitor,
    "script-step": lambda text: parse_script([(text, "press_report")]).steps[0].delay,
    "scenario-until": _until,
    "expectation": _expectation,
    "cli-until": _cli_until,
}

SPELLINGS = ["1h30m", "PT1H30M", "pt1h30m", "5400", "90 min", "1h 30min", "1.5 h", "5400s",
             "01:30", "01:30:00", "1.5 hours", "0.0625 days"]


@pytest.mark.parametrize("door", DURATION_DOORS)
@pytest.mark.parametrize("text", SPELLINGS)
def test_every_door_reads_the_same_durations(door: str, text: str) -> None:
    assert DURATION_DOORS[door](text) == pytest.approx(5400.0)


REFUSED = {
    "soon": "cannot read duration 'soon': not a duration",
    "1h30x": "cannot read duration '1h30x': not a duration",
    "90 parsecs": "cannot read duration '90 parsecs': not a duration",
    "PT": "cannot read duration 'PT': not a duration",
    "1e999": "cannot read duration '1e999': the number is too large",
}
#: texts a door reads as something else, as its standard says: XPDL 2.1's DeadlineDuration is
#: an Expression, so a bare name is a data field's value (which the engine refuses when the
#: package has no such field), not a misspelt duration; but text shaped like an ISO 8601
#: duration ('PT', 'PT5M5M') is a misspelt duration there too, refused as one
READ_OTHERWISE = {("xpdl-deadline", "soon")}


@pytest.mark.parametrize("door", DURATION_DOORS)
@pytest.mark.parametrize("text", REFUSED)
def test_every_door_refuses_the_same_durations_with_the_same_message(door: str, text: str
                                                                     ) -> None:
    if (door, text) in READ_OTHERWISE:
        assert isinstance(parse_duration_expression(text), Name)
        return
    with pytest.raises(OpspecError) as caught:
        DURATION_DOORS[door](text)
    message = str(caught.value)
    assert REFUSED[text] in message
    assert "\n" not in message, "a refusal is one line"
    assert "PT5M" in caught.value.hint, "the hint shows the spellings"


def test_a_refused_spec_duration_names_file_and_line() -> None:
    with pytest.raises(OpspecError, match=re.escape("s.xpdl:3: ")
                       + ".*cannot read duration 'soon': not a duration"):
        _directives("Period", "soon")


def test_negative_durations_are_refused_alike() -> None:
    for door in ("clock", "monitor", "scenario-until", "expectation", "sisarl-period"):
        with pytest.raises(OpspecError, match="cannot read duration '-5': a duration cannot be "
                                              "negative"):
            DURATION_DOORS[door]("-5")


# ---------------------------------------------------------------- times of day
def _timer(text: str) -> float:
    directives = _directives("StartTrigger", f"timer:{text}")
    trigger = directives.start_trigger
    return float(trigger.at[0])


def _script_at(text: str) -> float:
    return parse_script([(f"at {text}", "raise trg_1")]).steps[0].delay


def _xpdl_time_date(text: str) -> float:
    moment = parse_time_date(text)
    assert moment is not None and moment[1] is False
    return moment[0]


TIME_DOORS: dict[str, Callable[[str], float]] = {
    "clock": clock.parse_time_of_day,
    "sisarl-timer": _timer,
    "routine-window": lambda text: Window("w", text, "23:59").start,
    "script-at": _script_at,
}
TIMES = {"08:30": 30600.0, "8:30": 30600.0, "08:30:15": 30615.0, "8:30 am": 30600.0,
         "8:30 pm": 73800.0, "20:30": 73800.0, "00:00": 0.0}


@pytest.mark.parametrize("door", TIME_DOORS)
@pytest.mark.parametrize("text", TIMES)
def test_every_door_reads_the_same_times_of_day(door: str, text: str) -> None:
    assert TIME_DOORS[door](text) == pytest.approx(TIMES[text])


@pytest.mark.parametrize("text", ["08:30", "8:30", "08:30:15", "20:30"])
def test_xpdl_timer_dates_read_times_of_day_alike(text: str) -> None:
    assert _xpdl_time_date(text) == pytest.approx(TIMES[text])


BAD_TIMES = {
    "25:00": "cannot read time of day '25:00': it is past 24:00",
    "08:75": "cannot read time of day '08:75': expected HH:MM or HH:MM:SS",
    "13:00 pm": "cannot read time of day '13:00 pm': hours go from 1 to 12 with am/pm",
}


@pytest.mark.parametrize("door", TIME_DOORS)
@pytest.mark.parametrize("text", BAD_TIMES)
def test_every_door_refuses_the_same_times_with_the_same_message(door: str, text: str) -> None:
    with pytest.raises(OpspecError) as caught:
        TIME_DOORS[door](text)
    assert BAD_TIMES[text] in str(caught.value)
    assert "\n" not in str(caught.value)


# ---------------------------------------------------------------- writing
@pytest.mark.parametrize(("seconds", "text"), [
    (0.0, "d1 00:00:00"), (8 * 3600.0, "d1 08:00:00"), (86_400.0 + 90.25, "d2 00:01:30.250"),
    (59.9996, "d1 00:01:00"), (3 * 86_400.0 - 0.0001, "d4 00:00:00")])
def test_clock_times_are_written_one_way(seconds: float, text: str) -> None:
    assert clock.clock_time(seconds) == text


@pytest.mark.parametrize(("seconds", "text"), [
    (30600.0, "08:30"), (30615.0, "08:30:15"), (30615.5, "08:30:15.500"), (0.0, "00:00")])
def test_times_of_day_are_written_as_they_are_read(seconds: float, text: str) -> None:
    assert clock.time_of_day(seconds) == text
    assert clock.parse_time_of_day(text) == pytest.approx(seconds)


@pytest.mark.parametrize(("seconds", "text"), [
    (86_400.0, "1 day"), (2 * 86_400.0, "2 days"), (90_000.0, "25 h"), (14_400.0, "4 h"),
    (5400.0, "1.5 h"), (900.0, "15 min"), (90.0, "1.5 min"), (45.0, "45 s"), (0.25, "0.25 s"),
    (13_500.0, "3.75 h"), (66.0, "1.1 min"), (4.2 * 3600.0, "4.2 h"),
    # no number of the unit with two decimals: written in parts, as a person writes it (the
    # dispenser's mean walk, 1.19722 min before), to the millisecond
    (71.833, "1 min 11.833 s"), (4200.0, "1 h 10 min"), (14_120.0, "3 h 55 min 20 s"),
    (12342.857, "3 h 25 min 42.857 s"), (90061.0, "25 h 1 min 1 s"), (3630.0, "1 h 30 s")])
def test_spans_are_written_as_they_are_read(seconds: float, text: str) -> None:
    assert clock.span(seconds) == text
    assert clock.parse_duration(text) == pytest.approx(seconds)


@pytest.mark.parametrize("seconds", [119.9996, 3599.9996, 71.83333333, 86_399.9])
def test_a_span_in_parts_is_read_back_to_the_millisecond(seconds: float) -> None:
    text = clock.span(seconds)
    assert "." not in text.split()[0]          # no 1.19722 min, no 0.999999 h
    assert clock.parse_duration(text) == pytest.approx(seconds, abs=0.0005)
