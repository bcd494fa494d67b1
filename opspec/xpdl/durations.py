"""Read durations, times of day and rates as written in XPDL files, into seconds.

Accepted duration spellings (all give seconds as a float):

* ISO 8601: ``PT5M``, ``P1D``, ``PT0.5S``, ``P1DT2H``, ``P2W``, ``PT1,5H`` (a comma decimal
  works too). Years and months are nominal: a year is 365 days, a month 30 days.
* a plain number, meaning seconds: ``300``, ``0.5``, ``1e3``.
* numbers with units, optionally several: ``300 s``, ``5 min``, ``100ms``, ``2h``,
  ``1.5 days``, ``1h 30min``. Units: ``us``/``µs``, ``ms``, ``s``/``sec``/``second(s)``,
  ``m``/``min``/``minute(s)``, ``h``/``hr``/``hour(s)``, ``d``/``day(s)``, ``w``/``week(s)``,
  in any case.
* a clock-style duration ``HH:MM`` or ``HH:MM:SS[.fff]``: ``01:30`` is 90 minutes.

Negative durations are refused. :func:`parse_duration_expression` accepts all of the above or
an expression over data fields (``timeout * 60``, read by :mod:`opspec.xpdl.conditions`) whose
value the engine takes as seconds.
"""

from __future__ import annotations

import math
import re

from opspec.errors import SourceLocation, SpecError
from opspec.model.expressions import Expression, Literal
from opspec.xpdl.conditions import parse_expression

__all__ = [
    "parse_duration",
    "parse_duration_expression",
    "parse_rate",
    "parse_time_cycle",
    "parse_time_date",
    "parse_time_of_day",
]

_NUMBER = r"\d+(?:[.,]\d+)?"
_ISO = re.compile(
    rf"P(?:(?P<Y>{_NUMBER})Y)?(?:(?P<M>{_NUMBER})M)?(?:(?P<W>{_NUMBER})W)?(?:(?P<D>{_NUMBER})D)?"
    rf"(?:T(?:(?P<h>{_NUMBER})H)?(?:(?P<m>{_NUMBER})M)?(?:(?P<s>{_NUMBER})S)?)?",
    re.IGNORECASE,
)
_ISO_SECONDS = {
    "Y": 365 * 86_400.0, "M": 30 * 86_400.0, "W": 7 * 86_400.0, "D": 86_400.0,
    "h": 3600.0, "m": 60.0, "s": 1.0,
}
_PLAIN = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_WITH_UNIT = re.compile(r"\s*((?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*([a-zµ]+)\s*", re.IGNORECASE)
_CLOCK = re.compile(r"(\d{1,3}):([0-5]\d)(?::([0-5]\d(?:\.\d+)?))?")
_UNITS: dict[str, float] = {}
for _names, _seconds in (
    (("us", "µs", "usec", "microsecond", "microseconds"), 1e-6),
    (("ms", "msec", "msecs", "millisecond", "milliseconds"), 1e-3),
    (("s", "sec", "secs", "second", "seconds"), 1.0),
    (("m", "min", "mins", "minute", "minutes"), 60.0),
    (("h", "hr", "hrs", "hour", "hours"), 3600.0),
    (("d", "day", "days"), 86_400.0),
    (("w", "wk", "wks", "week", "weeks"), 7 * 86_400.0),
):
    for _name in _names:
        _UNITS[_name] = _seconds
_RATE_UNITS = {
    "hz": 1.0, "khz": 1000.0, "/s": 1.0, "/sec": 1.0, "/second": 1.0, "per second": 1.0,
    "/min": 1 / 60, "/minute": 1 / 60, "per minute": 1 / 60,
    "/h": 1 / 3600, "/hour": 1 / 3600, "per hour": 1 / 3600,
    "/d": 1 / 86_400, "/day": 1 / 86_400, "per day": 1 / 86_400,
}
_DURATION_HINT = "write e.g. PT5M, 300 (seconds), 5 min, 100ms, 1.5 days or 00:05:00"


def _error(what: str, text: str, problem: str, location: SourceLocation | None, hint: str) -> SpecError:
    return SpecError(f"cannot read {what} {text.strip()!r}: {problem}", location=location, hint=hint)


def _try_duration(text: str) -> float | None:
    """Seconds for a duration spelling, ``None`` when ``text`` is none of them."""
    stripped = text.strip()
    if not stripped:
        return None
    if stripped[0] in "pP":
        match = _ISO.fullmatch(stripped)
        parts = match.groupdict() if match else {}
        if not match or not any(parts.values()) or stripped.upper().endswith("T"):
            return None
        return sum(
            float(value.replace(",", ".")) * _ISO_SECONDS[key]
            for key, value in parts.items()
            if value
        )
    if _PLAIN.fullmatch(stripped):
        return float(stripped)
    clock = _CLOCK.fullmatch(stripped)
    if clock:
        hours, minutes, seconds = clock.groups()
        return int(hours) * 3600.0 + int(minutes) * 60.0 + float(seconds or 0)
    total, position = 0.0, 0
    while position < len(stripped):
        piece = _WITH_UNIT.match(stripped, position)
        if piece is None or piece.end() == position:
            return None
        factor = _UNITS.get(piece.group(2).lower())
        if factor is None:
            return None
        total += float(piece.group(1)) * factor
        position = piece.end()
    return total


def parse_duration(text: str, *, location: SourceLocation | None = None) -> float:
    """Seconds for a duration written in any of the module's spellings.

    Raises :class:`SpecError` (at ``location``) for anything else, for negative and for
    non-finite durations.
    """
    stripped = text.strip()
    if not stripped:
        raise _error("duration", text, "it is empty", location, _DURATION_HINT)
    seconds = _try_duration(stripped)
    if seconds is None:
        raise _error("duration", text, "not a duration", location, _DURATION_HINT)
    if seconds < 0:
        raise _error("duration", text, "a duration cannot be negative", location, _DURATION_HINT)
    if not math.isfinite(seconds):
        raise _error("duration", text, "the number is too large", location, _DURATION_HINT)
    return seconds


def parse_time_of_day(text: str, *, location: SourceLocation | None = None) -> float:
    """Seconds since midnight for ``HH:MM`` or ``HH:MM:SS[.fff]`` (24-hour clock, ``24:00``
    allowed as the end of the day), optionally followed by ``am``/``pm``."""
    hint = "write a 24-hour clock time such as 08:00, 17:30:15 or 8:00 pm"
    stripped = text.strip().lower()
    suffix = None
    for marker in ("am", "pm", "a.m.", "p.m."):
        if stripped.endswith(marker):
            suffix, stripped = marker[0], stripped[: -len(marker)].strip()
            break
    clock = _CLOCK.fullmatch(stripped)
    if clock is None:
        raise _error("time of day", text, "expected HH:MM or HH:MM:SS", location, hint)
    hours = int(clock.group(1))
    minutes, seconds = int(clock.group(2)), float(clock.group(3) or 0)
    if suffix is not None:
        if not 1 <= hours <= 12:
            raise _error("time of day", text, "hours go from 1 to 12 with am/pm", location, hint)
        hours = hours % 12 + (12 if suffix == "p" else 0)
    total = hours * 3600.0 + minutes * 60.0 + seconds
    if total > 86_400.0:
        raise _error("time of day", text, "it is past 24:00", location, hint)
    return total


def parse_rate(text: str, *, location: SourceLocation | None = None) -> float:
    """Events per second for ``10``, ``10Hz``, ``2.5 kHz``, ``10/s``, ``6 per minute``,
    ``3/h``, ``2/day``; a bare number means per second. The rate must be positive."""
    hint = "write e.g. 10Hz, 10/s, 6/min or 10 (per second)"
    stripped = text.strip()
    lowered = stripped.lower()
    number_text, factor = stripped, 1.0
    for unit in sorted(_RATE_UNITS, key=len, reverse=True):
        if lowered.endswith(unit):
            number_text, factor = stripped[: -len(unit)].strip(), _RATE_UNITS[unit]
            break
    if not _PLAIN.fullmatch(number_text):
        raise _error("rate", text, "not a rate", location, hint)
    rate = float(number_text) * factor
    if not (rate > 0 and math.isfinite(rate)):
        raise _error("rate", text, "a rate must be a positive, finite number", location, hint)
    return rate


def parse_duration_expression(
    text: str, *, location: SourceLocation | None = None
) -> Expression:
    """A Deadline duration: ``Literal(seconds)`` when ``text`` is a plain duration (``300``,
    ``PT5M``, ``5 min``), else the parsed expression (``timeout * 60``), whose value the engine
    takes as seconds. Raises :class:`SpecError` for empty text and
    :class:`~opspec.xpdl.conditions.ConditionSyntaxError` for unreadable expressions."""
    if not text.strip():
        raise _error("duration", text, "it is empty", location, _DURATION_HINT)
    seconds = _try_duration(text)
    if seconds is not None:
        return Literal(parse_duration(text, location=location))
    return parse_expression(text, location=location, kind="duration")


_DATE_TIME = re.compile(
    r"(?P<date>\d{4}-\d{2}-\d{2})(?:[T ](?P<time>\d{1,2}:\d{2}(?::\d{2}(?:[.,]\d+)?)?))?"
    r"(?P<zone>Z|[+-]\d{2}(?::?\d{2})?)?", re.IGNORECASE)
_TIME_ONLY = re.compile(r"T?(?P<time>\d{1,2}:\d{2}(?::\d{2}(?:[.,]\d+)?)?)"
                        r"(?P<zone>Z|[+-]\d{2}(?::?\d{2})?)?", re.IGNORECASE)
_TIMER_HINT = ("write a TimeDate as 2026-01-01T08:00:00 or 08:00, a TimeCycle as a duration "
               "(PT1H) or an ISO 8601 repeating interval (R3/PT7S, R/PT1H, "
               "R5/2026-01-01T08:00:00/PT1H)")


def parse_time_date(text: str, *, location: SourceLocation | None = None
                    ) -> tuple[float, bool] | None:
    """A timer's point in time: ``(seconds, calendar)``, or ``None`` when ``text`` is no date.

    ``2026-01-01T08:00:00`` (also with a space, seconds optional, a date alone meaning
    midnight) gives seconds since 1970-01-01 00:00 and ``calendar=True`` (the engine counts
    the package's earliest calendar date as day 1 of the run); a time of day ``08:00`` or
    ``T08:00:00`` gives seconds after day 1 00:00 and ``calendar=False``. A time-zone suffix
    (``Z``, ``+02:00``) is accepted and ignored: the simulated clock has no time zone.
    Impossible dates (``2026-02-30``) raise :class:`SpecError`."""
    import datetime as _dt

    stripped = text.strip()
    match = _DATE_TIME.fullmatch(stripped)
    if match is not None:
        try:
            day = _dt.date.fromisoformat(match.group("date"))
        except ValueError:
            raise _error("date", text, "no such date", location, _TIMER_HINT) from None
        seconds = 0.0
        if match.group("time"):
            seconds = parse_time_of_day(match.group("time").replace(",", "."), location=location)
        days = (day - _dt.date(1970, 1, 1)).days
        return days * 86_400.0 + seconds, True
    match = _TIME_ONLY.fullmatch(stripped)
    if match is not None:
        return parse_time_of_day(match.group("time").replace(",", "."), location=location), False
    return None


def parse_time_cycle(text: str, *, location: SourceLocation | None = None
                     ) -> tuple[int, float, tuple[float, bool] | None] | None:
    """An ISO 8601 repeating interval ``R[n]/[start/]duration``: ``(repeat, period, start)``
    where ``repeat`` is the number of firings (``-1``: ``R/…``, unbounded), ``period`` the
    duration in seconds and ``start`` a :func:`parse_time_date` value or ``None``. ``None``
    when ``text`` does not start with ``R``. Raises :class:`SpecError` for a malformed one."""
    stripped = text.strip()
    if not stripped[:1] in ("R", "r") or "/" not in stripped:
        return None
    parts = stripped.split("/")
    count_text = parts[0][1:]
    if count_text and not count_text.isdigit():
        raise _error("repeating interval", text, f"{parts[0]!r} is not R or Rn", location,
                     _TIMER_HINT)
    repeat = int(count_text) if count_text else -1
    if repeat == 0:
        raise _error("repeating interval", text, "R0 never fires", location, _TIMER_HINT)
    if len(parts) == 2:
        start, period_text = None, parts[1]
    elif len(parts) == 3:
        start = parse_time_date(parts[1], location=location)
        if start is None:
            raise _error("repeating interval", text, f"{parts[1]!r} is not a date-time",
                         location, _TIMER_HINT)
        period_text = parts[2]
    else:
        raise _error("repeating interval", text, "expected R[n]/[start/]duration", location,
                     _TIMER_HINT)
    period = parse_duration(period_text, location=location)
    if period <= 0:
        raise _error("repeating interval", text, "the period must be longer than zero",
                     location, _TIMER_HINT)
    return repeat, period, start
