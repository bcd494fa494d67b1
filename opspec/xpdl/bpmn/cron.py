"""A cron ``timeCycle`` as the ISO 8601 repeating interval it equals, when it equals one.

Camunda 7 (Quartz: ``sec min hour day-of-month month day-of-week [year]``, ``?`` for "no
value"), Zeebe (Spring: the same six fields) and Unix cron (``min hour dom month dow``) write
a timer cycle as a cron expression. croniter (a well-kept cron library) reads the fields
(ranges, steps, lists, names); opspec's timers fire on a fixed period, so a cron expression
is read when it fires every day at the same evenly spaced times — ``0 0/5 * * * ?`` is
``R/T00:00:00/PT5M``, ``0 8 * * *`` is ``R/T08:00:00/P1D`` — and refused, saying why, when it
does not (certain weekdays or days of the month, uneven times such as ``0 9,17 * * *``).
"""

from __future__ import annotations

import re

from opspec.errors import SourceLocation, SpecError

__all__ = ["cron_cycle"]

DAY = 86_400
_FIELD = re.compile(r"^[0-9A-Za-z*/,?#-]+$")
_WHOLE = ("day of the month", "month", "day of the week")


def cron_cycle(text: str, location: SourceLocation | None = None) -> str | None:
    """The ISO 8601 repeating interval ``text`` (a cron expression) equals; ``None`` when
    ``text`` is no cron expression. Raises :class:`SpecError` naming why a cron expression
    is no fixed period, or what croniter could not read."""
    fields = text.split()
    if len(fields) not in (5, 6, 7) or not all(_FIELD.match(f) for f in fields):
        return None
    if len(fields) == 5:                         # Unix: no seconds
        fields = ["0", *fields]
    if len(fields) == 7:                         # Quartz's optional year
        if fields[6] not in ("*", "?"):
            raise SpecError(f"the cron timeCycle {text!r} names years ({fields[6]}), which "
                            "no fixed period says", location=location)
        fields = fields[:6]
    seconds, minutes, hours, dom, month, dow = (f.replace("?", "*") for f in fields)
    from croniter import croniter  # type: ignore[import-untyped,unused-ignore]

    try:                       # croniter's own order: minute hour dom month dow second
        expanded = croniter(f"{minutes} {hours} {dom} {month} {dow} {seconds}").expanded
    except (ValueError, KeyError) as error:
        said = re.sub(r"^\[.*?\]\s*", "", str(error)) or "not a cron expression"
        raise SpecError(f"cannot read the cron timeCycle {text!r} (croniter: {said})",
                        location=location) from None
    mins, hrs, days, months, weekdays, secs = expanded
    sizes = (31, 12, 7)
    for what, values, size in zip(_WHOLE, (days, months, weekdays), sizes, strict=True):
        every = values == ["*"] or len({int(v) % 7 if size == 7 else int(v) for v in values
                                        if str(v).isdigit()}) == size
        if not every:
            raise SpecError(f"the cron timeCycle {text!r} fires on certain days only (its "
                            f"{what} field), which a fixed period cannot say",
                            location=location)
    times = sorted({h * 3600 + m * 60 + s
                    for h in _all(hrs, 24) for m in _all(mins, 60) for s in _all(secs, 60)})
    gaps = {b - a for a, b in zip(times, [*times[1:], times[0] + DAY], strict=True)}
    if len(gaps) != 1:
        shown = ", ".join(_clock(t) for t in times[:4]) + (", …" if len(times) > 4 else "")
        raise SpecError(f"the cron timeCycle {text!r} fires at uneven times of the day "
                        f"({shown}), which a fixed period cannot say", location=location)
    period = gaps.pop()
    return f"R/T{_clock(times[0])}/PT{period}S"


def _all(values: list[object], size: int) -> list[int]:
    return list(range(size)) if values == ["*"] else [int(str(v)) for v in values]


def _clock(seconds: int) -> str:
    return f"{seconds // 3600:02d}:{seconds % 3600 // 60:02d}:{seconds % 60:02d}"
