"""The text form of the property language, read by :func:`parse_property` (keywords in any
case; ``A``, ``B``, ``C`` are subjects (:mod:`opspec.properties.subjects`), durations are read
by :mod:`opspec.clock`: ``90``, ``90s``, ``5 min``, ``1h30m``, ``PT4H``)::


    never A                          absence: A never happens
    eventually A                     existence: A happens at least once
    min_gap A 4h                     no two A closer than 4 h   (also: never A twice within 4h)
    max_count A 4 per 24h            at most 4 A in any window of 24 h
    count A <= 4                     the number of A in the run (==, !=, <, <=, >, >=;
                                     count A in [1, 3])
    bounded_response A B 15min       every A is followed by a B within 15 min
                                     (also: B within 15 min after A)
    response A B                     every A is followed by a B before the run ends
    A before B                       precedence: no B before the first A
    A before each B                  every B has an A of its own before it
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence

from opspec.clock import parse_duration
from opspec.errors import ConfigurationError, SourceLocation
from opspec.properties.language import (
    COMPARISONS,
    BoundedResponse,
    CountBound,
    Eventually,
    MaxCount,
    MinGap,
    Never,
    NeverWhile,
    Precedence,
    Property,
)
from opspec.properties.subjects import read_subject, split_words

__all__ = ["FORMS", "looks_like_property", "parse_property", "read_property"]

FORMS = ("'min_gap A 4h' (or 'never A twice within 4h'), 'never A', 'eventually A', "
         "'max_count A 4 per 24h', 'count A <= 4' (==, !=, <, <=, >, >=, in [lo, hi]), "
         "'bounded_response A B 15min' (or 'B within 15min after A'), 'response A B', "
         "'A before B', 'A before each B', 'never_while A after B until C'")
_KEYWORDS = frozenset({"never", "eventually", "min_gap", "max_count", "count",
                       "bounded_response", "response", "never_while"})
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _seconds(text: str, *, zero: bool = False) -> float:
    value = parse_duration(text, error=ConfigurationError)
    if value < 0 or (value == 0 and not zero):
        raise ConfigurationError(f"{text!r} is not a {'' if zero else 'positive '}duration",
                                 hint="write e.g. 90s, 5 min, 4h or PT4H")
    return value


class _Syntax(Exception):
    """The text is not in any property form (not a mistake inside one)."""


def _expect(tokens: Sequence[str], i: int, word: str) -> int:
    if i >= len(tokens) or tokens[i].lower() != word:
        raise _Syntax
    return i + 1


def _number(tokens: Sequence[str], i: int) -> float:
    if i >= len(tokens) or not _NUMBER.fullmatch(tokens[i]):
        raise _Syntax
    return float(tokens[i])


def _bound(tokens: Sequence[str], i: int) -> float:
    """A count's bound: a word where it stands that is no number (a duration, a name, text
    in quotes) is a mistake inside the count form, said as one."""
    if i < len(tokens) and tokens[i] not in ("[", "]", ",") and not _NUMBER.fullmatch(tokens[i]):
        raise ConfigurationError(f"a count compares with a number (of events), not {tokens[i]!r}",
                                 hint="write e.g. 'count dispense <= 4' or "
                                      "'count dispense in [1, 4]'")
    return _number(tokens, i)


def _rest(tokens: Sequence[str], i: int) -> str:
    if i >= len(tokens):
        raise _Syntax
    return " ".join(tokens[i:])


def _read(tokens: list[str], text: str) -> tuple[Property, str | None]:
    """The property and the text of its duration (if it has one); :class:`_Syntax` when the
    tokens fit no form, :class:`ConfigurationError` for a mistake inside one."""
    head = tokens[0].lower() if tokens else ""
    try:
        if head in _KEYWORDS:
            a, i = read_subject(tokens, 1)
        else:
            a, i = read_subject(tokens, 0)
    except ConfigurationError:
        if head in _KEYWORDS or (len(tokens) > 1 and tokens[1].lower() in ("within", "before")):
            raise
        raise _Syntax from None
    end = len(tokens)
    if head == "never":
        if i == end:
            return Never(a, text=text), None
        i = _expect(tokens, _expect(tokens, i, "twice"), "within")
        gap = _rest(tokens, i)
        return MinGap(a, _seconds(gap), text=text), gap
    if head == "eventually" and i == end:
        return Eventually(a, text=text), None
    if head == "min_gap":
        gap = _rest(tokens, i)
        return MinGap(a, _seconds(gap), text=text), gap
    if head == "max_count":
        if i < len(tokens) and tokens[i].lower() != "per" and not _NUMBER.fullmatch(tokens[i]):
            raise ConfigurationError(f"{tokens[i]!r} is not a whole number >= 0",
                                     hint="write e.g. 'max_count dispense 4 per 24h'")
        limit = _number(tokens, i)
        if limit != int(limit) or limit < 0:
            raise ConfigurationError(f"{tokens[i]!r} is not a whole number >= 0",
                                     hint="write e.g. 'max_count dispense 4 per 24h'")
        gap = _rest(tokens, _expect(tokens, i + 1, "per"))
        return MaxCount(a, int(limit), _seconds(gap), text=text), None
    if head == "count":
        if i < end and tokens[i].lower() == "in":
            i = _expect(tokens, i + 1, "[")
            lo = _bound(tokens, i)
            hi = _bound(tokens, _expect(tokens, i + 1, ","))
            if _expect(tokens, i + 3, "]") != end:
                raise _Syntax
            return CountBound(a, "in", lo, hi, text=text), None
        if i < end and tokens[i] in COMPARISONS and i + 2 == end:
            return CountBound(a, tokens[i], _bound(tokens, i + 1), text=text), None
        raise _Syntax
    if head in ("bounded_response", "response", "never_while"):
        if head == "never_while":
            b, i = read_subject(tokens, _expect(tokens, i, "after"))
            c, i = read_subject(tokens, _expect(tokens, i, "until"))
            if i != end:
                raise _Syntax
            return NeverWhile(a, b, c, text=text), None
        b, i = read_subject(tokens, i)
        if head == "response":
            if i != end:
                raise _Syntax
            return BoundedResponse(a, b, math.inf, text=text), None
        if i < end and tokens[i].lower() == "within":
            i += 1
        gap = _rest(tokens, i)
        return BoundedResponse(a, b, _seconds(gap, zero=True), text=text), gap
    if head in _KEYWORDS:
        raise _Syntax
    word = tokens[i].lower() if i < end else ""
    if word == "before":
        each = i + 1 < end and tokens[i + 1].lower() == "each"
        b, j = read_subject(tokens, i + 2 if each else i + 1)
        if j != end:
            raise _Syntax
        return Precedence(a, b, each, text=text), None
    if word == "within":
        lowered = [t.lower() for t in tokens]
        if "after" not in lowered[i + 1:]:
            raise _Syntax
        at = end - 1 - lowered[::-1].index("after")
        gap = " ".join(tokens[i + 1:at])
        cause, j = read_subject(tokens, at + 1)
        if j != end or not gap:
            raise _Syntax
        return BoundedResponse(cause, a, _seconds(gap, zero=True), text=text), gap
    raise _Syntax


def looks_like_property(text: str) -> bool:
    """Whether ``text`` is written in one of the property forms (it may still hold a
    mistake, such as a bad duration)."""
    tokens = split_words(text)
    if not tokens:
        return False
    try:
        _read(tokens, text)
    except _Syntax:
        return False
    except ConfigurationError:
        return True
    return True


def read_property(text: str, *, what: str = "property",
                  location: SourceLocation | None = None) -> tuple[Property, str | None]:
    """:func:`parse_property`, and the text of the property's duration (or ``None``)."""
    cleaned = " ".join(text.split())
    try:
        return _read(split_words(cleaned), cleaned)
    except _Syntax:
        raise ConfigurationError(f"cannot read the {what} {cleaned!r}", location=location,
                                 hint=f"{what} forms: {FORMS}") from None
    except ConfigurationError as error:
        raise ConfigurationError(f"{what} {cleaned!r}: {error.message}", location=location,
                                 hint=error.hint) from None


def parse_property(text: str, *, what: str = "property",
                   location: SourceLocation | None = None) -> Property:
    """A property from its text form (whitespace is normalised: the cleaned text is its
    ``text``); :class:`ConfigurationError` at ``location`` when it cannot be read, naming it
    as a ``what`` ("monitor", "expectation") and listing the forms."""
    return read_property(text, what=what, location=location)[0]