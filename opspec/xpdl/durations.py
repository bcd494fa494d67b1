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
