"""What each term of the property language spelt in Python takes, refused clearly.

``count("x") == "3"``, ``within("a", "b", "5 min")``, ``min_gap(5, hours=1)``: a value of the
wrong kind raised a bare TypeError (or worse, a ValueError from ``float``) from inside opspec,
or was taken silently and never matched. Each is a
:class:`~opspec.errors.ConfigurationError` naming the term as written, the value and what
the term takes, which the pytest plugin shows as the test's line and one message.
"""

from __future__ import annotations

import math
from numbers import Real
from typing import Any

from opspec.errors import ConfigurationError

__all__ = ["described", "number", "text"]


def described(value: Any) -> str:
    """``value`` as a message names it: text is called text, a truth value one."""
    if isinstance(value, str):
        return f"the text {value!r}"
    if isinstance(value, bool):
        return f"the truth value {value!r}"
    return repr(value)


def _as_number(value: str) -> float | None:
    try:
        return float(value)
    except ValueError:
        return None


def _as_seconds(value: str) -> float | None:
    from opspec.clock import parse_duration

    try:
        return parse_duration(value, error=ConfigurationError)
    except ConfigurationError:
        return None


def number(term: str, value: Any, takes: str, *, seconds: bool = False) -> float:
    """``value`` as a float when it is a real number (not a truth value, not nan), else the
    refusal: ``term: takes ..., not ...`` with the number the text would be (``seconds``:
    a duration's seconds too, ``'5 min'`` is ``300``)."""
    if isinstance(value, Real) and not isinstance(value, bool) and not math.isnan(value):
        return float(value)
    hint = ""
    if isinstance(value, str):
        plain = _as_number(value.strip())
        timed = _as_seconds(value) if seconds and plain is None else None
        if plain is not None and not math.isnan(plain):
            hint = f"write {plain:g}, without quotes"
        elif timed is not None:
            hint = f"write {timed:g} (the seconds of {value!r})"
    raise ConfigurationError(f"{term}: {takes}, not {described(value)}", hint=hint)


def text(term: str, value: Any, takes: str) -> str:
    """``value`` when it is text, else the refusal ``term: takes ..., not ...``."""
    if isinstance(value, str):
        return value
    raise ConfigurationError(f"{term}: {takes}, not {described(value)}")
