"""XPDL's own time values: Deadline durations (a duration or an expression over data fields),
timer dates and ISO 8601 repeating intervals.

Durations, times of day and rates are read by :mod:`opspec.clock`, the one grammar every front
door uses; this module adds what only XPDL has. :func:`parse_duration_expression` accepts any
duration or an expression over data fields (``timeout * 60``, read by
:mod:`opspec.xpdl.conditions`) whose value the engine takes as seconds.
"""

from __future__ import annotations

import re

from opspec.clock import DURATION_HINT, is_duration, parse_duration, parse_time_of_day
from opspec.errors import SourceLocation, SpecError
from opspec.model.expressions import Expression, Literal
from opspec.xpdl.conditions import ConditionSyntaxError, parse_expression

__all__ = [
    "parse_duration",            # opspec.clock's, for callers not yet moved (commands/run.py)
    "parse_duration_expression",
    "parse_time_cycle",
    "parse_time_date",
]


def _error(what: str, text: str, problem: str, location: SourceLocation | None, hint: str) -> SpecError:
    return SpecError(f"cannot read {what} {text.strip()!r}: {problem}", location=location, hint=hint)


def parse_duration_expression(
    text: str, *, location: SourceLocation | None = None
) -> Expression:
    """A Deadline duration: ``Literal(seconds)`` when ``text`` is a plain duration (``300``,
    ``PT5M``, ``5 min``), else the parsed expression (``timeout * 60``), whose value the engine
    takes as seconds. Raises :class:`SpecError` for empty text and
    :class:`~opspec.xpdl.conditions.ConditionSyntaxError` for unreadable expressions; text
    that is no expression and has none of an expression's signs (``10 minuts``, ``1h30x``)
    was meant as a duration, and is refused as every other door refuses that duration."""
    if not text.strip():
        raise _error("duration", text, "it is empty", location, DURATION_HINT)
    if is_duration(text):
        return Literal(parse_duration(text, location=location))
    if _ISO_LIKE.fullmatch(text.strip()):
        # meant as ISO 8601, though it reads as a name ('PT5M5M') or a division ('R3/PT5M'):
        # refused as a duration, not as data fields named 'PT5M5M' or 'R3'
        _refuse_iso_like(text, location)
    try:
        return parse_expression(text, location=location, kind="duration")
    except ConditionSyntaxError:
        if EXPRESSION_SIGNS.isdisjoint(text):
            parse_duration(text, location=location)     # raises the grammar's refusal
        raise


#: characters only an expression has: unreadable text without one was meant as a duration
EXPRESSION_SIGNS = frozenset("+-*/%()<>=!&|?,;\"'[]{}")

#: an ISO 8601 duration's shape, misspelt ('PT', 'P1DT', 'PT5M5M', '-PT5M', 'P-1D'), or a
#: repeating interval (R3/PT5M, R/2026-01-01T08:00/P1D) where a duration goes; a data field
#: named like one (P1, R) is no such text: P and a digit need a unit after them, R a slash and
#: a P or a date
_ISO_LIKE = re.compile(r"[+-]?P[+-]?(T|\d+([.,]\d+)?[YMWDHS])[\dYMWDTHS.,]*"
                       r"|R\d*/(P|\d{4}-)\S*")


def _refuse_iso_like(text: str, location: SourceLocation | None) -> None:
    """Raise the duration grammar's refusal of ISO-8601-like ``text``; a repeating interval
    is said to be a cycle, which has its own place."""
    if text.strip().startswith("R"):
        raise _error("duration", text, "it is a repeating interval (a cycle), not a duration",
                     location, "write a duration such as PT5M here, or put the repeating "
                     "interval where a cycle goes (a timer's timeCycle / TimeCycle)")
    parse_duration(text, location=location)        # raises: it is no duration


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
