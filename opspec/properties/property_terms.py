"""The language's properties spelt in Python, each a predicate and a monitor alike:
``within`` (a bounded response), ``happens_before`` (a precedence), ``count(...) <= n``
(:class:`Count`), ``min_gap``, ``max_count_per``, ``never_while``, and ``monitor`` for any
text form. (``never`` and ``eventually`` are :mod:`opspec.properties.simple_predicates`.)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError
from opspec.properties import language, text_form
from opspec.properties.predicate import Predicate
from opspec.properties.simple_predicates import Holds, Match, as_match
from opspec.properties.term_arguments import number
from opspec.properties.term_arguments import text as text_of

__all__ = [
    "Count",
    "count",
    "happens_before",
    "max_count_per",
    "min_gap",
    "monitor",
    "never_while",
    "within",
]


def happens_before(a: str | Match | Callable[[TraceEvent], bool],
                   b: str | Match | Callable[[TraceEvent], bool], *,
                   each: bool = False) -> Predicate:
    """No ``b`` before the first ``a`` (``b`` may not happen at all; an event that is both
    precedes itself). ``each=True``: every ``b`` has its own earlier ``a`` (the n-th ``b``
    comes after the n-th ``a``). The property ``A before B`` (``A before each B``)."""
    first, then = as_match(a, "happens_before()"), as_match(b, "happens_before()")
    label = (f"happens_before({first.describe()}, {then.describe()}"
             f"{', each=True' if each else ''})")
    return Holds(language.Precedence(first.selector(), then.selector(), each), label)


def within(a: str | Match | Callable[[TraceEvent], bool],
           b: str | Match | Callable[[TraceEvent], bool], seconds: float) -> Predicate:
    """Every ``a`` is followed by a ``b`` at most ``seconds`` later (exactly ``seconds`` is in
    time; an event that is both answers itself). An ``a`` whose window is cut off by the end
    of the run is not judged; ``seconds=math.inf``: by the end of the run. The property
    ``bounded_response A B D`` (``B within D after A``)."""
    cause, response = as_match(a, "within()"), as_match(b, "within()")
    limit = number(f"within({cause.describe()}, {response.describe()}, {seconds!r})", seconds,
                   "seconds takes a number of seconds >= 0 (math.inf: by the end of the run)",
                   seconds=True)
    if limit < 0:
        raise ConfigurationError(f"within(): seconds must be >= 0, not {seconds!r}")
    return Holds(language.BoundedResponse(cause.selector(), response.selector(), limit),
                 f"within({cause.describe()}, {response.describe()}, {seconds:g} s)")


# ---------------------------------------------------------------- counting
class Count:
    """``count(x)``: compare with ``==``, ``!=``, ``<``, ``<=``, ``>``, ``>=``, or use
    :meth:`between`, :meth:`at_least`, :meth:`at_most`; each gives a :class:`Predicate`
    judged per trace (per replication, or per instance with ``per_instance``): the property
    ``count A OP n``."""

    __hash__ = None  # type: ignore[assignment]

    def __init__(self, match: Match) -> None:
        self.match = match

    def __repr__(self) -> str:
        return f"count({self.match.describe()})"

    def _bound(self, op: str, n: object, hi: object = None) -> Predicate:
        term = (f"{self!r}.between({n!r}, {hi!r})" if op == "in" else f"{self!r} {op} {n!r}")
        bound = language.CountBound(self.match.selector(), op, _number(term, n),
                                    None if hi is None else _number(term, hi))
        target = (f"between {bound.a:g} and {bound.b:g}" if op == "in"
                  else f"{op} {bound.a:g}")
        return Holds(bound, f"count({self.match.describe()}) {target}")

    def __eq__(self, n: object) -> Predicate:  # type: ignore[override]
        return self._bound("==", n)

    def __ne__(self, n: object) -> Predicate:  # type: ignore[override]
        return self._bound("!=", n)

    def __lt__(self, n: float) -> Predicate:
        return self._bound("<", n)

    def __le__(self, n: float) -> Predicate:
        return self._bound("<=", n)

    def __gt__(self, n: float) -> Predicate:
        return self._bound(">", n)

    def __ge__(self, n: float) -> Predicate:
        return self._bound(">=", n)

    def between(self, lo: float, hi: float) -> Predicate:
        """``lo <= count <= hi``."""
        if _number(f"{self!r}.between({lo!r}, {hi!r})", lo) > _number(
                f"{self!r}.between({lo!r}, {hi!r})", hi):
            raise ConfigurationError(f"count().between({lo}, {hi}): the range is empty")
        return self._bound("in", lo, hi)

    def at_least(self, n: float) -> Predicate:
        return self >= n

    def at_most(self, n: float) -> Predicate:
        return self <= n

    def exactly(self, n: float) -> Predicate:
        return self == n

    def of(self, events: Sequence[TraceEvent]) -> int:
        """How many events of ``events`` match."""
        return len(self.match.all(events))


def _number(term: str, n: object) -> float:
    return number(term, n, "a count compares with a number (of events)")


def count(what: str | Match | Callable[[TraceEvent], bool]) -> Count:
    """How many times ``what`` happens in a trace (see :class:`Count`)."""
    return Count(as_match(what, "count()"))


def _seconds(what: str, seconds: float, minutes: float, hours: float) -> float:
    total = (number(f"{what}()", seconds, "seconds= takes a number", seconds=True)
             + 60.0 * number(f"{what}()", minutes, "minutes= takes a number")
             + 3600.0 * number(f"{what}()", hours, "hours= takes a number"))
    if not total > 0:
        raise ConfigurationError(f"{what}(): the time must be positive",
                                 hint="give seconds=, minutes= or hours=")
    return total


def _subject(term: str, value: object) -> None:
    text_of(term, value, "an event is named by text ('dispense', 'trigger:trg_1', 'a|b')")


def _span_text(seconds: float) -> str:
    return f"{seconds / 3600:g}h" if seconds >= 3600 else f"{seconds:g}s"


def monitor(text: str) -> Predicate:
    """A property from its text form (``"min_gap dispense 4h"``, any form of
    :mod:`opspec.properties.language`)."""
    return Holds(text_form.parse_property(
        text_of("monitor()", text, "takes a property's text form ('min_gap dispense 4h')"),
        what="monitor"))


def min_gap(subject: str, *, seconds: float = 0, minutes: float = 0, hours: float = 0
            ) -> Predicate:
    """No two ``subject`` closer than the given time: ``min_gap("dispense", hours=4)``."""
    _subject("min_gap()", subject)
    gap = _seconds("min_gap", seconds, minutes, hours)
    return Holds(language.MinGap(language.parse_subject(subject), gap,
                                 text=f"min_gap {subject} {_span_text(gap)}"))


def never_while(subject: str, *, after: str, until: str) -> Predicate:
    """``subject`` never happens after an ``after`` and before the next ``until``."""
    for value in (subject, after, until):
        _subject("never_while()", value)
    return Holds(language.NeverWhile(
        language.parse_subject(subject), language.parse_subject(after),
        language.parse_subject(until), text=f"never_while {subject} after {after} until {until}"))


def max_count_per(subject: str, limit: int, *, seconds: float = 0, minutes: float = 0,
                  hours: float = 0) -> Predicate:
    """At most ``limit`` ``subject`` in any window of the given length."""
    if isinstance(limit, bool) or not isinstance(limit, int) or limit < 0:
        raise ConfigurationError(f"max_count_per(): limit must be a whole number >= 0, "
                                 f"not {limit!r}")
    _subject("max_count_per()", subject)
    window = _seconds("max_count_per", seconds, minutes, hours)
    return Holds(language.MaxCount(language.parse_subject(subject), limit, window,
                                   text=f"max_count {subject} {limit} per {_span_text(window)}"))
