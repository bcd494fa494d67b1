"""The simulated clock's values as text: one grammar to read durations, times of day and rates,
one way to write clock times and spans.

Every front door reads through here — XPDL Deadlines and timers, SISARL triggers and periods,
monitors (``min_gap dispense 1h30m``), scripts and scenario files, user-model routines, the
CLI's ``--until`` — so a spelling one accepts, all accept, and one refused is refused with the
same message. Each door passes its own error class and location (``file:line`` of a spec,
``path: key`` of a TOML file) and may put its own context in front of the message.

Durations (all give seconds as a float):

* ISO 8601: ``PT5M``, ``P1D``, ``PT0.5S``, ``P1DT2H``, ``P2W``, ``PT1,5H`` (a comma decimal
  works too). Years and months are nominal: a year is 365 days, a month 30 days.
* a plain number, meaning seconds: ``300``, ``0.5``, ``1e3``.
* numbers with units, optionally several: ``300 s``, ``5 min``, ``100ms``, ``2h``,
  ``1.5 days``, ``1h 30min``, ``1h30m``. Units: ``us``/``µs``, ``ms``, ``s``/``sec``/
  ``second(s)``, ``m``/``min``/``minute(s)``, ``h``/``hr``/``hour(s)``, ``d``/``day(s)``,
  ``w``/``week(s)``, in any case.
* a clock-style duration ``HH:MM`` or ``HH:MM:SS[.fff]``: ``01:30`` is 90 minutes.

Negative and non-finite durations are refused.

Times of day: ``HH:MM`` or ``HH:MM:SS[.fff]`` on a 24-hour clock (``24:00`` is the end of the
day), optionally followed by ``am``/``pm``.

Rates: ``10``, ``10Hz``, ``2.5 kHz``, ``10/s``, ``6 per minute``, ``3/h``, ``2/day``.

Writing: :func:`clock_time` (``d1 08:00:00``, the timeline of ``opspec run``, traces and
violations), :func:`time_of_day` (``08:00``), :func:`span` (``4 h``, ``1 min 11.833 s``) and
:func:`figure` (a measured value as ``opspec run`` and the walkthrough print a metric:
``97.49 s``). A trace event as a line of text is :mod:`opspec.engine.trace_text`'s.

Pure Python, depends only on :mod:`opspec.errors`: every layer may use it, the engine too.
"""

from __future__ import annotations

import math
import re
from typing import Final, Protocol

from opspec.errors import OpspecError, SourceLocation, SpecError

__all__ = [
    "DAY",
    "DURATION_HINT",
    "ErrorClass",
    "clock_time",
    "figure",
    "is_duration",
    "parse_duration",
    "parse_rate",
    "parse_time_of_day",
    "span",
    "time_of_day",
    "try_duration",
]

DAY: Final = 86_400.0

#: what a refused duration's message suggests, at every front door
DURATION_HINT: Final = ("write e.g. PT5M (ISO 8601), 300 (seconds), 5 min, 1h30m, 1.5 days or "
                        "00:05:00")
_TIME_HINT: Final = "write a 24-hour clock time such as 08:00, 17:30:15 or 8:00 pm"
_RATE_HINT: Final = "write e.g. 10Hz, 10/s, 6/min or 10 (per second)"


class ErrorClass(Protocol):
    """An :class:`~opspec.errors.OpspecError` subclass (its constructor's shape)."""

    def __call__(self, message: str, *, location: SourceLocation | None = ...,
                 hint: str = ...) -> OpspecError: ...


_NUMBER = r"\d+(?:[.,]\d+)?"
_ISO = re.compile(
    rf"P(?:(?P<Y>{_NUMBER})Y)?(?:(?P<M>{_NUMBER})M)?(?:(?P<W>{_NUMBER})W)?(?:(?P<D>{_NUMBER})D)?"
    rf"(?:T(?:(?P<h>{_NUMBER})H)?(?:(?P<m>{_NUMBER})M)?(?:(?P<s>{_NUMBER})S)?)?",
    re.IGNORECASE,
)
_ISO_SECONDS: Final = {
    "Y": 365 * DAY, "M": 30 * DAY, "W": 7 * DAY, "D": DAY, "h": 3600.0, "m": 60.0, "s": 1.0,
}
_PLAIN = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_WITH_UNIT = re.compile(r"\s*((?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*([a-zµ]+)\s*", re.IGNORECASE)
_CLOCK = re.compile(r"(\d{1,3}):([0-5]\d)(?::([0-5]\d(?:\.\d+)?))?")


def _units() -> dict[str, float]:
    units: dict[str, float] = {}
    for names, seconds in (
        (("us", "µs", "usec", "microsecond", "microseconds"), 1e-6),
        (("ms", "msec", "msecs", "millisecond", "milliseconds"), 1e-3),
        (("s", "sec", "secs", "second", "seconds"), 1.0),
        (("m", "min", "mins", "minute", "minutes"), 60.0),
        (("h", "hr", "hrs", "hour", "hours"), 3600.0),
        (("d", "day", "days"), DAY),
        (("w", "wk", "wks", "week", "weeks"), 7 * DAY),
    ):
        for name in names:
            units[name] = seconds
    return units


_UNITS: Final = _units()
_RATE_UNITS: Final = {
    "hz": 1.0, "khz": 1000.0, "/s": 1.0, "/sec": 1.0, "/second": 1.0, "per second": 1.0,
    "/min": 1 / 60, "/minute": 1 / 60, "per minute": 1 / 60,
    "/h": 1 / 3600, "/hour": 1 / 3600, "per hour": 1 / 3600,
    "/d": 1 / DAY, "/day": 1 / DAY, "per day": 1 / DAY,
}


def _refuse(error: ErrorClass, what: str, text: str, problem: str,
            location: SourceLocation | None, hint: str) -> OpspecError:
    return error(f"cannot read {what} {text.strip()!r}: {problem}", location=location,
                 hint=hint)


def _read_duration(stripped: str) -> float | None:
    """Seconds for a duration spelling (any sign), ``None`` when ``stripped`` is none."""
    if not stripped:
        return None
    if stripped[0] in "pP":
        match = _ISO.fullmatch(stripped)
        parts = match.groupdict() if match else {}
        if not match or not any(parts.values()) or stripped.upper().endswith("T"):
            return None
        return sum(float(value.replace(",", ".")) * _ISO_SECONDS[key]
                   for key, value in parts.items() if value)
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


def is_duration(text: str) -> bool:
    """Whether ``text`` is spelled as a duration, even one :func:`parse_duration` refuses as
    negative or too large (so that it is refused as a duration, not read as something else)."""
    return _read_duration(text.strip()) is not None


def try_duration(text: str) -> float | None:
    """Seconds for ``text`` when :func:`parse_duration` would accept it, else ``None`` (for
    places where text may be a duration or something else, such as an expression)."""
    seconds = _read_duration(text.strip())
    if seconds is None or seconds < 0 or not math.isfinite(seconds):
        return None
    return seconds


def parse_duration(text: str, *, location: SourceLocation | None = None,
                   error: ErrorClass = SpecError) -> float:
    """Seconds for a duration in any of the module's spellings; ``error`` (at ``location``)
    for anything else, for negative and for non-finite durations."""
    stripped = text.strip()
    if not stripped:
        raise _refuse(error, "duration", text, "it is empty", location, DURATION_HINT)
    seconds = _read_duration(stripped)
    if seconds is None:
        raise _refuse(error, "duration", text, "not a duration", location, DURATION_HINT)
    if seconds < 0:
        raise _refuse(error, "duration", text, "a duration cannot be negative", location,
                      DURATION_HINT)
    if not math.isfinite(seconds):
        raise _refuse(error, "duration", text, "the number is too large", location,
                      DURATION_HINT)
    return seconds


def parse_time_of_day(text: str, *, location: SourceLocation | None = None,
                      error: ErrorClass = SpecError) -> float:
    """Seconds since midnight for ``HH:MM`` or ``HH:MM:SS[.fff]`` (24-hour clock, ``24:00``
    allowed as the end of the day), optionally followed by ``am``/``pm``."""
    stripped = text.strip().lower()
    suffix = None
    for marker in ("am", "pm", "a.m.", "p.m."):
        if stripped.endswith(marker):
            suffix, stripped = marker[0], stripped[: -len(marker)].strip()
            break
    clock = _CLOCK.fullmatch(stripped)
    if clock is None:
        raise _refuse(error, "time of day", text, "expected HH:MM or HH:MM:SS", location,
                      _TIME_HINT)
    hours = int(clock.group(1))
    minutes, seconds = int(clock.group(2)), float(clock.group(3) or 0)
    if suffix is not None:
        if not 1 <= hours <= 12:
            raise _refuse(error, "time of day", text, "hours go from 1 to 12 with am/pm",
                          location, _TIME_HINT)
        hours = hours % 12 + (12 if suffix == "p" else 0)
    total = hours * 3600.0 + minutes * 60.0 + seconds
    if total > DAY:
        raise _refuse(error, "time of day", text, "it is past 24:00", location, _TIME_HINT)
    return total


def parse_rate(text: str, *, location: SourceLocation | None = None,
               error: ErrorClass = SpecError) -> float:
    """Events per second for ``10``, ``10Hz``, ``2.5 kHz``, ``10/s``, ``6 per minute``,
    ``3/h``, ``2/day``; a bare number means per second. The rate must be positive."""
    stripped = text.strip()
    lowered = stripped.lower()
    number_text, factor = stripped, 1.0
    for unit in sorted(_RATE_UNITS, key=len, reverse=True):
        if lowered.endswith(unit):
            number_text, factor = stripped[: -len(unit)].strip(), _RATE_UNITS[unit]
            break
    if not _PLAIN.fullmatch(number_text):
        raise _refuse(error, "rate", text, "not a rate", location, _RATE_HINT)
    rate = float(number_text) * factor
    if not (rate > 0 and math.isfinite(rate)):
        raise _refuse(error, "rate", text, "a rate must be a positive, finite number",
                      location, _RATE_HINT)
    return rate


# ---------------------------------------------------------------- writing
def clock_time(seconds: float) -> str:
    """``d1 08:00:00`` for simulated seconds (day 1 is the first day), ``d1 08:00:00.250``
    when there is a fraction of a second: the one way opspec shows a point of the run."""
    millis = round(max(0.0, seconds) * 1000.0)     # 59.9996 s shows as the next minute
    day, rest = divmod(millis, 86_400_000)
    hours, rest = divmod(rest, 3_600_000)
    minutes, rest = divmod(rest, 60_000)
    secs, frac = divmod(rest, 1000)
    tail = f".{frac:03d}" if frac else ""
    return f"d{day + 1} {hours:02d}:{minutes:02d}:{secs:02d}{tail}"


def time_of_day(seconds: float) -> str:
    """Seconds after midnight as ``08:00``, ``08:00:30`` or ``08:00:30.250`` (what
    :func:`parse_time_of_day` reads back)."""
    millis = round(seconds * 1000.0)
    hours, rest = divmod(millis, 3_600_000)
    minutes, rest = divmod(rest, 60_000)
    secs, frac = divmod(rest, 1000)
    text = f"{hours:02d}:{minutes:02d}"
    if frac:
        return f"{text}:{secs:02d}.{frac:03d}"
    return f"{text}:{secs:02d}" if secs else text


def span(seconds: float) -> str:
    """A length of time for people, in the largest unit that reads well: ``2 days``,
    ``4 h``, ``1.5 h``, ``3.75 h``, ``15 min``, ``1.5 min``, ``45 s``, ``0.25 s``; a length
    that is no number of hours or minutes with at most two decimals is written in parts, to
    the millisecond as :func:`clock_time` is: ``1 min 11.833 s``, ``1 h 10 min`` (what
    :func:`parse_duration` reads back)."""
    for unit, size in (("day", DAY), ("h", 3600.0), ("min", 60.0)):
        if seconds >= size and (seconds % size == 0 or unit != "day"):
            count = seconds / size
            if unit == "day" or _two_decimals(count):
                plural = "s" if unit == "day" and count != 1 else ""
                return f"{count:g} {unit}{plural}"
            return _parts(seconds)
    return f"{seconds:g} s"


def _two_decimals(count: float) -> bool:
    """Whether ``count`` is written exactly with at most two decimals (``3.75``, not the
    ``1.19722`` of 71.833 s in minutes), allowing for the float's rounding (``4.2 * 3600``)."""
    hundredths = count * 100.0
    return abs(hundredths - round(hundredths)) <= 1e-9 * max(1.0, hundredths)


def _parts(seconds: float) -> str:
    """``1 h 25 min 42.857 s`` for a span of a minute and more that :func:`span` cannot
    write as one number of its unit: whole hours and minutes, then the seconds to the
    millisecond (``1.19722 min`` is not how anyone writes 71.833 s)."""
    millis = round(seconds * 1000.0)
    hours, rest = divmod(millis, 3_600_000)
    minutes, rest = divmod(rest, 60_000)
    parts = [f"{count} {unit}" for count, unit in ((hours, "h"), (minutes, "min")) if count]
    if rest:
        parts.append(f"{rest / 1000:g} s")
    return " ".join(parts)


def figure(value: object, unit: str = "") -> str:
    """A measured value for people, as ``opspec run`` prints a metric: 4 significant digits
    for a float (``97.49 s``), a count as it is, ``-`` for none (a mean of no samples)."""
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.4g}{unit}"
    return f"{value}{unit}"
