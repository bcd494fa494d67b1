"""Evaluate condition trees against data fields: JavaScript-like, but predictable.

The front end parses condition text once (:mod:`opspec.xpdl.conditions`); this module gives the
trees a meaning. :func:`evaluate` walks a tree; :func:`compile_expression` turns it once into
nested closures, several times faster, for the engine's hot path. Both share every rule below.

Values are ``None`` (null), booleans, ints, floats, text, and for dotted names records
(mappings) and lists. The rules:

* **Truthiness** (``!``, ``&&``, ``||``, a condition's result): ``null``, ``false``, ``0``,
  ``0.0``, NaN, empty lists/records, and the texts ``""``, ``"false"`` and ``"0"`` (ignoring
  case and surrounding space) are false; everything else is true. The text rule is where we
  leave JavaScript on purpose: XPDL data often holds ``"false"``.
* ``&&`` and ``||`` short-circuit and always return a boolean.
* **Equality** ``==``/``!=``: ``null`` equals only ``null``; two texts compare exactly (case
  matters); numbers compare numerically (``true == 1``); a number and a text holding a number
  compare numerically (``3 == "3"``, ``"3.0" == 3``), a text holding no number equals no number;
  a boolean and a text compare the text, ignoring case and space, to ``"true"``/``"false"``
  (``"TRUE" == true``); anything else uses Python equality.
* **Ordering** ``< <= > >=``: numbers (and booleans) numerically; two texts as text
  (``"10" < "9"``, as in JavaScript); a number and a text holding a number numerically. Any
  other pair (a number and ``"abc"``, anything and ``null``) is an :class:`ExecutionError`, not a
  silent ``false``.
* **Arithmetic**: ``+`` concatenates when either side is text (``"a" + 1`` is ``"a1"``), else
  adds numbers. ``- * / %`` need numbers or texts holding numbers. ``/`` always gives a float;
  ``%`` takes the sign of the left operand (JavaScript/Java remainder). Dividing by zero is an
  :class:`ExecutionError`.
* **Names**: a data field missing from the data is an :class:`ExecutionError` naming the field
  and listing the fields that exist. ``a.b`` looks ``b`` up in the record ``a``; ``x.length``
  of a text or list is its length.
* **Functions**: the whitelist in :mod:`opspec.model.functions`. ``str`` writes ``null``,
  ``true``/``false`` and integral floats without ``.0`` (as JavaScript does); ``int`` truncates;
  ``round`` rounds half away from zero; ``compare`` is ``0`` for equal values by the equality
  rule, else the ordering. The time helpers read the *simulation* clock: ``now()`` (seconds),
  ``time_of_day()`` (``now() % 86400``), ``hour()`` and ``day()`` (integers).

Every problem raises :class:`opspec.errors.ExecutionError` quoting the condition.
"""

from __future__ import annotations

import functools
import math
import operator
import re
from collections.abc import Callable, Mapping, Sized
from decimal import ROUND_HALF_UP, Decimal
from typing import Any, NoReturn

from opspec.errors import ExecutionError, SourceLocation
from opspec.model.expression_text import to_text
from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary
from opspec.model.functions import FUNCTIONS

__all__ = [
    "CompiledCondition",
    "CompiledExpression",
    "compile_condition",
    "compile_expression",
    "evaluate",
    "evaluate_condition",
    "truthy",
]

CompiledExpression = Callable[[Mapping[str, Any], float], Any]
"""``f(data, now)``: the value of a compiled expression; ``now`` is the simulated time."""
CompiledCondition = Callable[[Mapping[str, Any], float], bool]

_DAY = 86_400.0
_FALSE_TEXTS = frozenset({"", "false", "0"})
_NUMERIC_TEXT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


class _Problem(Exception):
    """Raised deep inside evaluation; turned into an ExecutionError quoting the condition."""


# --------------------------------------------------------------------------- value rules


def truthy(value: Any) -> bool:
    """Whether ``value`` counts as true (the rules in the module docstring)."""
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
def _numeric_text(text: str) -> int | float | None:
    """The number a text holds, or ``None``."""
    stripped = text.strip()
    if len(stripped) > 400 or not _NUMERIC_TEXT.fullmatch(stripped):
        return None
    try:
        return int(stripped)
    except ValueError:
        return float(stripped)


def _as_number(value: Any, what: str) -> int | float:
    if isinstance(value, (int, float)):  # bool is an int
        return value
    if isinstance(value, str):
        number = _numeric_text(value)
        if number is not None:
            return number
    raise _Problem(f"{what} needs a number, got {_show(value)}")


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


def _equal(a: Any, b: Any) -> bool:
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
            number = _numeric_text(a)
            return number is not None and number == b
        return False
    return bool(a == b)


def _order(a: Any, b: Any) -> int:
    """-1, 0 or 1; raises for pairs that have no order."""
    return -1 if _ordered(a, b, "<") else (1 if _ordered(a, b, ">") else 0)


def _ordered_number(value: Any) -> int | float | None:
    if isinstance(value, (int, float)):
        return value
    if isinstance(value, str):
        return _numeric_text(value)
    return None


def _less(a: Any, b: Any) -> bool:
    return _ordered(a, b, "<")


_FAST_ORDERING: dict[str, Callable[[Any, Any], bool]] = {
    "<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge,
}


def _ordered(a: Any, b: Any, op: str) -> bool:
    """``a op b`` for an ordering operator, by the ordering rules (NaN compares false)."""
    test = _FAST_ORDERING[op]
    if isinstance(a, str) and isinstance(b, str):
        return test(a, b)
    x, y = _ordered_number(a), _ordered_number(b)
    if x is None or y is None:
        culprit = a if x is None else b
        raise _Problem(
            f"cannot compare {_show(a)} {op} {_show(b)}: {_text(culprit)} is not a number"
        )
    return test(x, y)


def _add(a: Any, b: Any) -> Any:
    if isinstance(a, str) or isinstance(b, str):
        return _text(a) + _text(b)
    return _as_number(a, "'+'") + _as_number(b, "'+'")


def _subtract(a: Any, b: Any) -> Any:
    return _as_number(a, "'-'") - _as_number(b, "'-'")


def _multiply(a: Any, b: Any) -> Any:
    return _as_number(a, "'*'") * _as_number(b, "'*'")


def _divide(a: Any, b: Any) -> float:
    x, y = _as_number(a, "'/'"), _as_number(b, "'/'")
    if y == 0:
        raise _Problem(f"division by zero ({_text(a)} / {_text(b)})")
    return x / y


def _remainder(a: Any, b: Any) -> int | float:
    x, y = _as_number(a, "'%'"), _as_number(b, "'%'")
    if y == 0:
        raise _Problem(f"remainder of a division by zero ({_text(a)} % {_text(b)})")
    if isinstance(x, int) and isinstance(y, int):
        r = abs(x) % abs(y)
        return r if x >= 0 else -r
    return math.fmod(x, y)


_ARITHMETIC: dict[str, Callable[[Any, Any], Any]] = {
    "+": _add, "-": _subtract, "*": _multiply, "/": _divide, "%": _remainder,
}


# --------------------------------------------------------------------------- functions


def _integral(value: Any, what: str) -> float:
    number = float(_as_number(value, what))
    if not math.isfinite(number):
        raise _Problem(f"{what} needs a finite number, got {_text(value)}")
    return number


def _round(value: Any, digits: Any = 0) -> int | float:
    number = _integral(value, "round()")
    places = _as_number(digits, "round()'s second argument")
    if not isinstance(places, int) or isinstance(places, bool) or abs(places) > 30:
        raise _Problem(f"round() needs a whole number of digits, got {_text(digits)}")
    rounded = Decimal(repr(number)).quantize(Decimal(1).scaleb(-places), ROUND_HALF_UP)
    return int(rounded) if places <= 0 else float(rounded)


def _to_int(value: Any) -> int:
    if isinstance(value, int):
        return int(value)
    return int(_integral(value, "int()"))


def _length(value: Any) -> int:
    if isinstance(value, (str, list, tuple, Mapping)):
        return len(value)
    raise _Problem(f"len() needs a text, list or record, got {_show(value)}")


def _contains(container: Any, item: Any) -> bool:
    if isinstance(container, str):
        return _text(item) in container
    if isinstance(container, (list, tuple)):
        return any(_equal(element, item) for element in container)
    if isinstance(container, Mapping):
        return item in container
    raise _Problem(f"contains() needs a text, list or record, got {_show(container)}")


def _extreme(pick_less: bool) -> Callable[..., Any]:
    def extreme(*values: Any) -> Any:
        if len(values) == 1 and isinstance(values[0], (list, tuple)):
            values = tuple(values[0])
        if not values:
            raise _Problem("min()/max() of an empty list")
        best = values[0]
        for value in values[1:]:
            if _less(value, best) if pick_less else _less(best, value):
                best = value
        return best

    return extreme


def _compare(a: Any, b: Any) -> int:
    return 0 if _equal(a, b) else _order(a, b)


_IMPLEMENTATIONS: dict[str, Callable[..., Any]] = {
    "abs": lambda x: abs(_as_number(x, "abs()")),
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
    "float": lambda x: float(_as_number(x, "float()")),
    "bool": truthy,
}
_TIME: dict[str, Callable[[float], Any]] = {
    "now": lambda now: now,
    "time_of_day": lambda now: now % _DAY,
    "hour": lambda now: int((now % _DAY) // 3600),
    "day": lambda now: int(now // _DAY),
}
assert set(_IMPLEMENTATIONS) | set(_TIME) == set(FUNCTIONS), "whitelist and evaluator disagree"


# --------------------------------------------------------------------------- names


def _missing(data: Mapping[str, Any], name: str) -> NoReturn:
    fields = sorted(str(key) for key in data)
    shown = ", ".join(fields[:30]) + (", ..." if len(fields) > 30 else "")
    raise _Problem(
        f"data field {name!r} does not exist (fields: {shown or 'none'})"
    )


def _member(value: Any, path: tuple[str, ...], index: int) -> Any:
    """Follow ``path[index:]`` from ``value`` (the value of ``path[:index]``)."""
    for i in range(index, len(path)):
        key = path[i]
        if isinstance(value, Mapping):
            if key not in value:
                keys = ", ".join(sorted(str(k) for k in value)) or "none"
                raise _Problem(
                    f"record {'.'.join(path[:i])!r} has no member {key!r} (members: {keys})"
                )
            value = value[key]
        elif key == "length" and isinstance(value, (str, list, tuple)):
            value = len(value)
        else:
            raise _Problem(
                f"{'.'.join(path[:i])!r} is {_kind(value)}, so it has no member {key!r}"
            )
    return value


def _lookup(data: Mapping[str, Any], path: tuple[str, ...]) -> Any:
    try:
        value = data[path[0]]
    except KeyError:
        _missing(data, path[0])
    return _member(value, path, 1) if len(path) > 1 else value


# --------------------------------------------------------------------------- errors


def _fail(
    expr: Expression, problem: BaseException, location: SourceLocation | None, now: float | None
) -> ExecutionError:
    try:
        text = to_text(expr)
    except ValueError:
        text = repr(expr)
    hint = ""
    if "does not exist" in str(problem):
        hint = "declare the data field in the process or package, or fix the name"
    return ExecutionError(
        f"cannot evaluate condition `{text}`: {problem}",
        location=location,
        hint=hint,
        sim_time=now,
    )


_PYTHON_ERRORS = (TypeError, ValueError, ArithmeticError)


# --------------------------------------------------------------------------- tree walker


def evaluate(
    expr: Expression,
    data: Mapping[str, Any],
    *,
    clock: Callable[[], float] | None = None,
    location: SourceLocation | None = None,
) -> Any:
    """The value of ``expr`` over ``data`` by walking the tree (no compilation step).

    ``clock`` gives the simulated time for the time helpers; without one, ``now()`` and its
    kin raise. Raises :class:`ExecutionError` (located at ``location``) for every problem.
    """
    try:
        return _walk(expr, data, clock)
    except (_Problem, *_PYTHON_ERRORS) as problem:
        now = clock() if clock is not None else None
        raise _fail(expr, problem, location, now) from None


def evaluate_condition(
    expr: Expression,
    data: Mapping[str, Any],
    *,
    clock: Callable[[], float] | None = None,
    location: SourceLocation | None = None,
) -> bool:
    """Whether ``expr`` holds over ``data`` (its value under :func:`truthy`)."""
    return truthy(evaluate(expr, data, clock=clock, location=location))


def _walk(expr: Expression, data: Mapping[str, Any], clock: Callable[[], float] | None) -> Any:
    if isinstance(expr, Literal):
        return expr.value
    if isinstance(expr, Name):
        return _lookup(data, expr.path)
    if isinstance(expr, Binary):
        op = expr.op
        if op == "and":
            return truthy(_walk(expr.left, data, clock)) and truthy(_walk(expr.right, data, clock))
        if op == "or":
            return truthy(_walk(expr.left, data, clock)) or truthy(_walk(expr.right, data, clock))
        left = _walk(expr.left, data, clock)
        right = _walk(expr.right, data, clock)
        if op == "==":
            return _equal(left, right)
        if op == "!=":
            return not _equal(left, right)
        if op in _FAST_ORDERING:
            return _ordered(left, right, op)
        if op in _ARITHMETIC:
            return _ARITHMETIC[op](left, right)
        raise _Problem(f"unknown operator {op!r}")
    if isinstance(expr, Unary):
        value = _walk(expr.operand, data, clock)
        if expr.op == "not":
            return not truthy(value)
        if expr.op == "neg":
            return -_as_number(value, "'-'")
        raise _Problem(f"unknown operator {expr.op!r}")
    if isinstance(expr, Call):
        if expr.function in _TIME:
            if clock is None:
                raise _Problem(f"{expr.function}() needs the simulation clock, none was given")
            return _TIME[expr.function](clock())
        function = _IMPLEMENTATIONS.get(expr.function)
        if function is None:
            raise _Problem(f"unknown function {expr.function!r}")
        return function(*[_walk(arg, data, clock) for arg in expr.args])
    raise _Problem(f"not an expression node: {expr!r}")


# --------------------------------------------------------------------------- compiler


def compile_expression(
    expr: Expression, *, location: SourceLocation | None = None
) -> CompiledExpression:
    """``expr`` turned once into nested closures: ``f(data, now)`` gives its value.

    Same semantics as :func:`evaluate`, several times faster (see ``benchmarks/``): node types
    are dispatched once here, not on every call, constants and single names are inlined into
    their parent's closure, and same-type comparisons take a fast path. ``now`` is the
    simulated time the time helpers read.
    """
    try:
        inner = _compile(expr)
    except _Problem as problem:
        raise _fail(expr, problem, location, None) from None

    def run(data: Mapping[str, Any], now: float) -> Any:
        try:
            return inner(data, now)
        except (_Problem, *_PYTHON_ERRORS) as problem:
            raise _fail(expr, problem, location, now) from None

    return run


def compile_condition(
    expr: Expression | None, *, location: SourceLocation | None = None
) -> CompiledCondition:
    """Like :func:`compile_expression` but the result is a boolean; ``None`` (no condition)
    compiles to a function that is always true."""
    if expr is None:
        return lambda data, now: True
    inner = compile_expression(expr, location=location)
    return lambda data, now: truthy(inner(data, now))


_Fn = Callable[[Mapping[str, Any], float], Any]


def _compile(expr: Expression) -> _Fn:
    if isinstance(expr, Literal):
        value = expr.value
        return lambda data, now: value
    if isinstance(expr, Name):
        return _compile_name(expr.path)
    if isinstance(expr, Unary):
        operand = _compile(expr.operand)
        if expr.op == "not":
            return lambda data, now: not truthy(operand(data, now))
        if expr.op == "neg":
            return lambda data, now: -_as_number(operand(data, now), "'-'")
        raise _Problem(f"unknown operator {expr.op!r}")
    if isinstance(expr, Binary):
        return _compile_binary(expr)
    if isinstance(expr, Call):
        return _compile_call(expr)
    raise _Problem(f"not an expression node: {expr!r}")


def _compile_name(path: tuple[str, ...]) -> _Fn:
    root = path[0]
    if len(path) == 1:

        def field(data: Mapping[str, Any], now: float) -> Any:
            try:
                return data[root]
            except KeyError:
                _missing(data, root)

        return field
    return lambda data, now: _lookup(data, path)


def _compile_binary(expr: Binary) -> _Fn:
    op = expr.op
    left, right = _compile(expr.left), _compile(expr.right)
    if op == "and":

        def both(data: Mapping[str, Any], now: float) -> bool:
            a = left(data, now)
            if not (a is True or (a is not False and truthy(a))):
                return False
            b = right(data, now)
            return b is True or (b is not False and truthy(b))

        return both
    if op == "or":

        def either(data: Mapping[str, Any], now: float) -> bool:
            a = left(data, now)
            if a is True or (a is not False and truthy(a)):
                return True
            b = right(data, now)
            return b is True or (b is not False and truthy(b))

        return either
    if op in ("==", "!="):
        return _compile_equality(expr, left, right, negate=op == "!=")
    if op in _FAST_ORDERING:
        return _compile_ordering(expr, left, right)
    if op in _ARITHMETIC:
        arithmetic = _ARITHMETIC[op]
        return lambda data, now: arithmetic(left(data, now), right(data, now))
    raise _Problem(f"unknown operator {op!r}")


def _compile_equality(expr: Binary, left: _Fn, right: _Fn, *, negate: bool) -> _Fn:
    # The common shape "field == 'constant'" gets one closure with both operands inlined.
    if isinstance(expr.left, Name) and len(expr.left.path) == 1 and isinstance(
        expr.right, Literal
    ):
        root, constant = expr.left.path[0], expr.right.value
        kind = type(constant)

        def field_equals(data: Mapping[str, Any], now: float) -> bool:
            try:
                value = data[root]
            except KeyError:
                _missing(data, root)
            if type(value) is kind:
                return (value == constant) is not negate
            return _equal(value, constant) is not negate

        return field_equals

    if isinstance(expr.right, Literal):
        fixed = expr.right.value
        fixed_kind = type(fixed)

        def equals_constant(data: Mapping[str, Any], now: float) -> bool:
            a = left(data, now)
            if type(a) is fixed_kind:
                return (a == fixed) is not negate
            return _equal(a, fixed) is not negate

        return equals_constant

    def equals(data: Mapping[str, Any], now: float) -> bool:
        a, b = left(data, now), right(data, now)
        if type(a) is type(b) and type(a) in (str, int, float, bool):
            return (a == b) is not negate
        return _equal(a, b) is not negate

    return equals


def _compile_ordering(expr: Binary, left: _Fn, right: _Fn) -> _Fn:
    op = expr.op
    fast = _FAST_ORDERING[op]
    constant = expr.right.value if isinstance(expr.right, Literal) else None
    if (
        isinstance(expr.left, Name) and len(expr.left.path) == 1
        and type(constant) in (int, float)
    ):
        # "field < 3": the field read and the constant inlined, numbers compared directly.
        root = expr.left.path[0]

        def field_ordering(data: Mapping[str, Any], now: float) -> bool:
            try:
                value = data[root]
            except KeyError:
                _missing(data, root)
            kind = type(value)
            if kind is int or kind is float:
                return fast(value, constant)
            if kind is str:  # XPDL data often holds numbers as text ("3")
                number = _numeric_text(value)
                if number is not None:
                    return fast(number, constant)
            return _ordered(value, constant, op)

        return field_ordering
    if type(constant) in (int, float):

        def ordering_constant(data: Mapping[str, Any], now: float) -> bool:
            value = left(data, now)
            kind = type(value)
            if kind is int or kind is float:
                return fast(value, constant)
            return _ordered(value, constant, op)

        return ordering_constant

    def ordering(data: Mapping[str, Any], now: float) -> bool:
        a, b = left(data, now), right(data, now)
        ta, tb = type(a), type(b)
        if (ta is int or ta is float) and (tb is int or tb is float):
            return fast(a, b)
        if ta is str and tb is str:
            return fast(a, b)
        return _ordered(a, b, op)

    return ordering


def _compile_call(expr: Call) -> _Fn:
    if expr.function in _TIME:
        helper = _TIME[expr.function]
        return lambda data, now: helper(now)
    function = _IMPLEMENTATIONS.get(expr.function)
    if function is None:
        raise _Problem(f"unknown function {expr.function!r}")
    args = tuple(_compile(arg) for arg in expr.args)
    if len(args) == 1:
        (only,) = args
        return lambda data, now: function(only(data, now))
    if len(args) == 2:
        first, second = args
        return lambda data, now: function(first(data, now), second(data, now))
    return lambda data, now: function(*[arg(data, now) for arg in args])
