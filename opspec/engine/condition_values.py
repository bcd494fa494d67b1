"""The value rules behind condition evaluation: truthiness, equality, ordering, arithmetic, the
whitelisted functions and data-field lookup.

:mod:`opspec.engine.conditions` documents these rules and uses them from both the tree walker
and the compiled closures, so the two cannot drift apart. Problems raise :class:`ConditionProblem`, which
the evaluator turns into an :class:`~opspec.errors.ExecutionError` quoting the condition.
"""

from __future__ import annotations

import functools
import math
import operator
import re
from collections.abc import Callable, Mapping, Sized
from decimal import ROUND_HALF_UP, Decimal
from typing import Any, NoReturn

from opspec.model.functions import FUNCTIONS

__all__ = [
    "ARITHMETIC",
    "FAST_ORDERING",
    "IMPLEMENTATIONS",
    "TIME_HELPERS",
    "ConditionProblem",
    "as_number",
    "equal",
    "lookup",
    "missing_field",
    "numeric_text",
    "ordered",
    "truthy",
]

_DAY = 86_400.0
_FALSE_TEXTS = frozenset({"", "false", "0"})
_NUMERIC_TEXT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


class ConditionProblem(Exception):
    """Raised deep inside evaluation; turned into an ExecutionError quoting the condition."""


# --------------------------------------------------------------------------- value rules


def truthy(value: Any) -> bool:
    """Whether ``value`` counts as true (rules in :mod:`opspec.engine.conditions`)."""
    if value is None or value is False:
        return False
    if value is True:
        return True
    if isinstance(value, (int, float)):
        return value != 0 and not (isinstance(value, float) and math.isnan(value))
    if isinstance(value, str):
        return value.strip().lower() not in _FALSE_TEXTS
    if isinstance(value, Sized):
        return len(value) > 0
    return True


def _kind(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, (int, float)):
        return "number"
    if isinstance(value, str):
        return "text"
    if isinstance(value, Mapping):
        return "record"
    if isinstance(value, (list, tuple)):
        return "list"
    return type(value).__name__


def _show(value: Any) -> str:
    if value is None:
        return "null"
    shown = repr(value) if isinstance(value, str) else _text(value)
    return f"{shown} ({_kind(value)})"


@functools.lru_cache(maxsize=4096)  # data texts repeat; the regex dominates mixed comparisons
def numeric_text(text: str) -> int | float | None:
    """The number a text holds, or ``None``."""
    stripped = text.strip()
    if len(stripped) > 400 or not _NUMERIC_TEXT.fullmatch(stripped):
        return None
    try:
        return int(stripped)
    except ValueError:
        return float(stripped)


def as_number(value: Any, what: str) -> int | float:
    if isinstance(value, (int, float)):  # bool is an int
        return value
    if isinstance(value, str):
        number = numeric_text(value)
        if number is not None:
            return number
    raise ConditionProblem(f"{what} needs a number, got {_show(value)}")


def _text(value: Any) -> str:
    if value is None:
        return "null"
    if value is True:
        return "true"
    if value is False:
        return "false"
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e21:
        return str(int(value))
    return value if isinstance(value, str) else str(value)


def equal(a: Any, b: Any) -> bool:
    if a is None or b is None:
        return a is None and b is None
    if isinstance(a, str) and isinstance(b, str):
        return a == b
    if isinstance(b, str):
        a, b = b, a
    if isinstance(a, str):  # b is not text
        if isinstance(b, bool):
            return a.strip().lower() == ("true" if b else "false")
        if isinstance(b, (int, float)):
            number = numeric_text(a)
            return number is not None and number == b
        return False
    return bool(a == b)


def _order(a: Any, b: Any) -> int:
    """-1, 0 or 1; raises for pairs that have no order."""
    return -1 if ordered(a, b, "<") else (1 if ordered(a, b, ">") else 0)


def _ordered_number(value: Any) -> int | float | None:
    if isinstance(value, (int, float)):
        return value
    if isinstance(value, str):
        return numeric_text(value)
    return None


def _less(a: Any, b: Any) -> bool:
    return ordered(a, b, "<")


FAST_ORDERING: dict[str, Callable[[Any, Any], bool]] = {
    "<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge,
}


def ordered(a: Any, b: Any, op: str) -> bool:
    """``a op b`` for an ordering operator, by the ordering rules (NaN compares false)."""
    test = FAST_ORDERING[op]
    if isinstance(a, str) and isinstance(b, str):
        return test(a, b)
    x, y = _ordered_number(a), _ordered_number(b)
    if x is None or y is None:
        culprit = a if x is None else b
        raise ConditionProblem(
            f"cannot compare {_show(a)} {op} {_show(b)}: {_text(culprit)} is not a number"
        )
    return test(x, y)


#: Values a spec's arithmetic may make (issue 33: a script that doubles a value each step must
#: stop with a located error, not exhaust memory): texts up to MAX_TEXT characters, integers
#: below 2**MAX_INT_BITS in magnitude (floats overflow to inf by themselves).
MAX_TEXT = 1_000_000
MAX_INT_BITS = 1024
_MAX_INT = 1 << MAX_INT_BITS


def _bounded(value: Any, op: str) -> Any:
    if type(value) is int and not -_MAX_INT < value < _MAX_INT:
        raise ConditionProblem(
            f"the integer {op} makes has more than {MAX_INT_BITS} bits: a value that grows "
            "without bound (does something double it on every step?)")
    return value


def _add(a: Any, b: Any) -> Any:
    if type(a) in _NUMBERS and type(b) in _NUMBERS:     # the common case, first
        return _bounded(a + b, "'+'")
    if isinstance(a, str) or isinstance(b, str):
        x, y = _text(a), _text(b)
        if len(x) + len(y) > MAX_TEXT:
            raise ConditionProblem(
                f"'+' would make a text of {len(x) + len(y):,} characters, more than "
                f"{MAX_TEXT:,}: a value that grows without bound (does something append to it "
                "on every step?)")
        return x + y
    if isinstance(a, _VECTORS) or isinstance(b, _VECTORS):
        return _elementwise(a, b, "+", operator.add, scalar=False)
    return _bounded(as_number(a, "'+'") + as_number(b, "'+'"), "'+'")


def _subtract(a: Any, b: Any) -> Any:
    if type(a) in _NUMBERS and type(b) in _NUMBERS:
        return _bounded(a - b, "'-'")
    if isinstance(a, _VECTORS) or isinstance(b, _VECTORS):
        return _elementwise(a, b, "-", operator.sub, scalar=False)
    return _bounded(as_number(a, "'-'") - as_number(b, "'-'"), "'-'")


def _multiply(a: Any, b: Any) -> Any:
    if type(a) in _NUMBERS and type(b) in _NUMBERS:
        return _bounded(a * b, "'*'")
    if isinstance(a, _VECTORS) or isinstance(b, _VECTORS):
        return _elementwise(a, b, "*", operator.mul, scalar=True)
    return _bounded(as_number(a, "'*'") * as_number(b, "'*'"), "'*'")


_VECTORS = (tuple, list)
_NUMBERS = frozenset({int, float, bool})


def _elementwise(a: Any, b: Any, op: str, fn: Callable[[Any, Any], Any], *,
                 scalar: bool) -> tuple[Any, ...]:
    """Vector arithmetic (array data, e.g. poses): vector op vector of the same length, and
    for '*' and '/' a number and a vector (each element scaled)."""
    what = f"'{op}'"
    if isinstance(a, _VECTORS) and isinstance(b, _VECTORS):
        if len(a) != len(b):
            raise ConditionProblem(f"cannot {what} vectors of lengths {len(a)} and {len(b)}")
        return tuple(fn(as_number(x, what), as_number(y, what)) for x, y in zip(a, b))
    if not scalar:
        raise ConditionProblem(f"{what} needs two numbers or two vectors, got {_show(a)} and {_show(b)}")
    if isinstance(a, _VECTORS):
        k = as_number(b, what)
        return tuple(fn(as_number(x, what), k) for x in a)
    k = as_number(a, what)
    return tuple(fn(k, as_number(y, what)) for y in b)


def _divide(a: Any, b: Any) -> Any:
    if isinstance(a, _VECTORS) and not isinstance(b, _VECTORS):
        if as_number(b, "'/'") == 0:
            raise ConditionProblem(f"division by zero ({_text(a)} / {_text(b)})")
        return _elementwise(a, b, "/", operator.truediv, scalar=True)
    x, y = as_number(a, "'/'"), as_number(b, "'/'")
    if y == 0:
        raise ConditionProblem(f"division by zero ({_text(a)} / {_text(b)})")
    return x / y


def _remainder(a: Any, b: Any) -> int | float:
    x, y = as_number(a, "'%'"), as_number(b, "'%'")
    if y == 0:
        raise ConditionProblem(f"remainder of a division by zero ({_text(a)} % {_text(b)})")
    if isinstance(x, int) and isinstance(y, int):
        r = abs(x) % abs(y)
        return r if x >= 0 else -r
    return math.fmod(x, y)


ARITHMETIC: dict[str, Callable[[Any, Any], Any]] = {
    "+": _add, "-": _subtract, "*": _multiply, "/": _divide, "%": _remainder,
}


# --------------------------------------------------------------------------- functions


def _integral(value: Any, what: str) -> float:
    number = float(as_number(value, what))
    if not math.isfinite(number):
        raise ConditionProblem(f"{what} needs a finite number, got {_text(value)}")
    return number


def _round(value: Any, digits: Any = 0) -> int | float:
    number = _integral(value, "round()")
    places = as_number(digits, "round()'s second argument")
    if not isinstance(places, int) or isinstance(places, bool) or abs(places) > 30:
        raise ConditionProblem(f"round() needs a whole number of digits, got {_text(digits)}")
    rounded = Decimal(repr(number)).quantize(Decimal(1).scaleb(-places), ROUND_HALF_UP)
    return int(rounded) if places <= 0 else float(rounded)


def _to_int(value: Any) -> int:
    if isinstance(value, int):
        return int(value)
    return int(_integral(value, "int()"))


def _length(value: Any) -> int:
    if isinstance(value, (str, list, tuple, Mapping)):
        return len(value)
    raise ConditionProblem(f"len() needs a text, list or record, got {_show(value)}")


def _contains(container: Any, item: Any) -> bool:
    if isinstance(container, str):
        return _text(item) in container
    if isinstance(container, (list, tuple)):
        return any(equal(element, item) for element in container)
    if isinstance(container, Mapping):
        return item in container
    raise ConditionProblem(f"contains() needs a text, list or record, got {_show(container)}")


def _extreme(pick_less: bool) -> Callable[..., Any]:
    def extreme(*values: Any) -> Any:
        if len(values) == 1 and isinstance(values[0], (list, tuple)):
            values = tuple(values[0])
        if not values:
            raise ConditionProblem("min()/max() of an empty list")
        best = values[0]
        for value in values[1:]:
            if _less(value, best) if pick_less else _less(best, value):
                best = value
        return best

    return extreme


def _compare(a: Any, b: Any) -> int:
    return 0 if equal(a, b) else _order(a, b)


IMPLEMENTATIONS: dict[str, Callable[..., Any]] = {
    "abs": lambda x: abs(as_number(x, "abs()")),
    "min": _extreme(True),
    "max": _extreme(False),
    "round": _round,
    "floor": lambda x: math.floor(_integral(x, "floor()")),
    "ceil": lambda x: math.ceil(_integral(x, "ceil()")),
    "len": _length,
    "lower": lambda x: _text(x).lower(),
    "upper": lambda x: _text(x).upper(),
    "strip": lambda x: _text(x).strip(),
    "contains": _contains,
    "startswith": lambda a, b: _text(a).startswith(_text(b)),
    "endswith": lambda a, b: _text(a).endswith(_text(b)),
    "find": lambda a, b: _text(a).find(_text(b)),
    "compare": _compare,
    "str": _text,
    "int": _to_int,
    "float": lambda x: float(as_number(x, "float()")),
    "bool": truthy,
}
TIME_HELPERS: dict[str, Callable[[float], Any]] = {
    "now": lambda now: now,
    "time_of_day": lambda now: now % _DAY,
    "hour": lambda now: int((now % _DAY) // 3600),
    "day": lambda now: int(now // _DAY),
}
assert set(IMPLEMENTATIONS) | set(TIME_HELPERS) == set(FUNCTIONS), "whitelist and evaluator disagree"


# --------------------------------------------------------------------------- names


def missing_field(data: Mapping[str, Any], name: str) -> NoReturn:
    fields = sorted(str(key) for key in data)
    shown = ", ".join(fields[:30]) + (", ..." if len(fields) > 30 else "")
    raise ConditionProblem(
        f"data field {name!r} does not exist (fields: {shown or 'none'})"
    )


def _member(value: Any, path: tuple[str, ...], index: int) -> Any:
    """Follow ``path[index:]`` from ``value`` (the value of ``path[:index]``)."""
    for i in range(index, len(path)):
        key = path[i]
        if isinstance(value, Mapping):
            if key not in value:
                keys = ", ".join(sorted(str(k) for k in value)) or "none"
                raise ConditionProblem(
                    f"record {'.'.join(path[:i])!r} has no member {key!r} (members: {keys})"
                )
            value = value[key]
        elif key == "length" and isinstance(value, (str, list, tuple)):
            value = len(value)
        else:
            raise ConditionProblem(
                f"{'.'.join(path[:i])!r} is {_kind(value)}, so it has no member {key!r}"
            )
    return value


def lookup(data: Mapping[str, Any], path: tuple[str, ...]) -> Any:
    try:
        value = data[path[0]]
    except KeyError:
        missing_field(data, path[0])
    return _member(value, path, 1) if len(path) > 1 else value
