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

import sys
import types
from collections.abc import Callable, Mapping
from typing import Any, Final, final

from opspec.engine.condition_values import (
    ARITHMETIC,
    FAST_ORDERING,
    IMPLEMENTATIONS,
    TIME_HELPERS,
    ConditionProblem,
    as_number,
    equal,
    lookup,
    missing_field,
    numeric_text,
    ordered,
    truthy,
)
from opspec.errors import ExecutionError, SourceLocation
from opspec.model.expression_text import to_text
from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary

__all__ = [
    "CompiledCondition",
    "CompiledExpression",
    "Constant",
    "compile_condition",
    "compile_expression",
    "constant_value",
    "evaluate",
    "evaluate_condition",
    "field_name",
    "truthy",
]

CompiledExpression = Callable[[Mapping[str, Any], float], Any]
"""``f(data, now)``: the value of a compiled expression; ``now`` is the simulated time."""
CompiledCondition = Callable[[Mapping[str, Any], float], bool]
"""``f(data, now)``: whether a compiled condition holds."""


def field_name(name: str) -> str:
    """``name`` as the one string object of its text (``sys.intern``): the names a run reads
    and writes data fields by. A dictionary finds a key by identity before comparing the
    text, so the compiled data dictionaries' keys, the assignments' targets, the names the
    conditions read and the engine's own literals (interned by Python and by mypyc) meet
    without a comparison of characters; otherwise the names parsed from the spec are
    separate strings and each look-up compares them (about 300 instructions a robot's
    workflow instance)."""
    return sys.intern(name) if type(name) is str else name


def _value(literal: Literal) -> Any:
    """A literal's value, a string interned (:func:`field_name`): the values a constant
    assignment writes are then found by identity where they are compared or looked up (a
    robot's commands, ``COMMANDS[command]``)."""
    return field_name(literal.value) if type(literal.value) is str else literal.value


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
    except (ConditionProblem, *_PYTHON_ERRORS) as problem:
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
        return lookup(data, expr.path)
    if isinstance(expr, Binary):
        op = expr.op
        if op == "and":
            return truthy(_walk(expr.left, data, clock)) and truthy(_walk(expr.right, data, clock))
        if op == "or":
            return truthy(_walk(expr.left, data, clock)) or truthy(_walk(expr.right, data, clock))
        left = _walk(expr.left, data, clock)
        right = _walk(expr.right, data, clock)
        if op == "==":
            return equal(left, right)
        if op == "!=":
            return not equal(left, right)
        if op in FAST_ORDERING:
            return ordered(left, right, op)
        if op in ARITHMETIC:
            return ARITHMETIC[op](left, right)
        raise ConditionProblem(f"unknown operator {op!r}")
    if isinstance(expr, Unary):
        value = _walk(expr.operand, data, clock)
        if expr.op == "not":
            return not truthy(value)
        if expr.op == "neg":
            return -as_number(value, "'-'")
        raise ConditionProblem(f"unknown operator {expr.op!r}")
    if isinstance(expr, Call):
        if expr.function in TIME_HELPERS:
            if clock is None:
                raise ConditionProblem(f"{expr.function}() needs the simulation clock, none was given")
            return TIME_HELPERS[expr.function](clock())
        function = IMPLEMENTATIONS.get(expr.function)
        if function is None:
            raise ConditionProblem(f"unknown function {expr.function!r}")
        return function(*[_walk(arg, data, clock) for arg in expr.args])
    raise ConditionProblem(f"not an expression node: {expr!r}")


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
    if isinstance(expr, Literal):
        # a constant cannot fail: no wrapper (an assignment of a constant is common, and
        # from source each closure level is a Python call)
        value = _value(expr)
        if COMPILED:        # (its value read natively where the engine runs assignments)
            return Constant(value)
        constant = lambda data, now: value
        constant.opspec_constant = (value,)  # type: ignore[attr-defined]   # for the plans
        return constant
    try:
        own = _compile_root(expr, (expr, location))
        if own is not None:
            return own
        inner = _compile(expr)
    except ConditionProblem as problem:
        raise _fail(expr, problem, location, None) from None

    def run(data: Mapping[str, Any], now: float) -> Any:
        try:
            return inner(data, now)
        except (ConditionProblem, *_PYTHON_ERRORS) as problem:
            raise _fail(expr, problem, location, now) from None

    return run


@final
class Constant:
    """A constant expression's function, compiled (:func:`compile_expression`): called, its
    ``value``; ``Flow.assign`` reads the value without the call (compiled, a call of a
    closure goes through Python's calling convention, the simulated time boxed for it:
    about 150 instructions an assignment of a constant, two a robot's period)."""

    def __init__(self, value: Any) -> None:
        self.value = value

    def __call__(self, data: Mapping[str, Any], now: float) -> Any:
        return self.value


def constant_value(evaluator: Callable[..., Any]) -> tuple[Any] | None:
    """``(value,)`` when ``evaluator`` is :func:`compile_expression`'s function of a constant
    (from source only), else ``None``: the plans write the value in place of the call."""
    found: tuple[Any] | None = getattr(evaluator, "opspec_constant", None)
    return found


#: the operators whose closures give a bool (see :func:`compile_condition`)
_BOOLEAN: Final = frozenset({"==", "!=", "and", "or"})


def compile_condition(
    expr: Expression | None, *, location: SourceLocation | None = None
) -> CompiledCondition:
    """Like :func:`compile_expression` but the result is a boolean; ``None`` (no condition)
    compiles to a function that is always true."""
    if expr is None:
        return lambda data, now: True
    try:
        if isinstance(expr, Binary) and (expr.op in _BOOLEAN or expr.op in FAST_ORDERING):
            # a comparison's or a conjunction's closure gives a bool and, as the root, names
            # the condition in its own errors: no wrapper (from source each closure level is
            # a Python call; compiled, a call through Python's calling convention)
            return _compile_binary(expr, (expr, location))
        inner = _compile(expr)
    except ConditionProblem as problem:
        raise _fail(expr, problem, location, None) from None

    # (one closure, not compile_expression's wrapped in another: a call between compiled
    # closures goes through Python's calling convention)
    def holds(data: Mapping[str, Any], now: float) -> bool:
        try:
            value = inner(data, now)
        except (ConditionProblem, *_PYTHON_ERRORS) as problem:
            raise _fail(expr, problem, location, now) from None
        return value is True or (value is not False and truthy(value))

    return holds


_Fn = Callable[[Mapping[str, Any], float], Any]
#: the whole expression and its place, given to the closure at an expression's root: it then
#: turns its own problems into :func:`_fail`'s error (``None`` below the root: the problem
#: goes up to the root's closure as it is)
_Whole = tuple[Expression, SourceLocation | None] | None

#: whether this module runs compiled (mypyc): a constant's closure is then native code and
#: the plans keep calling it (see :func:`constant_value`)
COMPILED: Final = not isinstance(_fail, types.FunctionType)


def _compile_root(expr: Expression, whole: _Whole) -> _Fn | None:
    """The closure of ``expr`` at an expression's root, ``whole``, for a shape whose closure
    answers for its own errors; ``None`` for any other (the caller wraps it)."""
    if isinstance(expr, Name) and len(expr.path) == 1:
        return _compile_name(expr.path, whole)
    if isinstance(expr, Call) and expr.function in TIME_HELPERS:
        return _compile_call(expr, whole)
    if (isinstance(expr, Binary) and expr.op in ARITHMETIC and isinstance(expr.left, Name)
            and len(expr.left.path) == 1 and isinstance(expr.right, Literal)):
        return _compile_binary(expr, whole)
    return None


def _compile(expr: Expression) -> _Fn:
    if isinstance(expr, Literal):
        value = _value(expr)
        return lambda data, now: value
    if isinstance(expr, Name):
        return _compile_name(expr.path)
    if isinstance(expr, Unary):
        operand = _compile(expr.operand)
        if expr.op == "not":
            return lambda data, now: not truthy(operand(data, now))
        if expr.op == "neg":
            return lambda data, now: -as_number(operand(data, now), "'-'")
        raise ConditionProblem(f"unknown operator {expr.op!r}")
    if isinstance(expr, Binary):
        return _compile_binary(expr)
    if isinstance(expr, Call):
        return _compile_call(expr)
    raise ConditionProblem(f"not an expression node: {expr!r}")


def _compile_name(path: tuple[str, ...], whole: _Whole = None) -> _Fn:
    root = field_name(path[0])
    if len(path) == 1:

        def field(data: Mapping[str, Any], now: float) -> Any:
            try:
                try:
                    return data[root]
                except KeyError:
                    missing_field(data, root)
            except (ConditionProblem, *_PYTHON_ERRORS) as problem:
                raise _at_root(whole, problem, now) from None

        return field
    return lambda data, now: lookup(data, path)


def _compile_binary(expr: Binary, whole: _Whole = None) -> _Fn:
    op = expr.op
    left, right = _compile(expr.left), _compile(expr.right)
    # (``and`` and ``or`` give a bool: at a condition's root, ``whole``, they are the
    # condition, naming it in their operands' errors as ``compile_condition``'s wrapper would;
    # ``now`` untyped: compiled, a float parameter is unboxed on entry and boxed again for
    # each operand's call, where the caller's box can be handed on)
    if op == "and":

        def both(data: Mapping[str, Any], now: Any) -> bool:
            try:
                a = left(data, now)
                if not (a is True or (a is not False and truthy(a))):
                    return False
                b = right(data, now)
                return b is True or (b is not False and truthy(b))
            except (ConditionProblem, *_PYTHON_ERRORS) as problem:
                raise _at_root(whole, problem, now) from None

        return both
    if op == "or":

        def either(data: Mapping[str, Any], now: Any) -> bool:
            try:
                a = left(data, now)
                if a is True or (a is not False and truthy(a)):
                    return True
                b = right(data, now)
                return b is True or (b is not False and truthy(b))
            except (ConditionProblem, *_PYTHON_ERRORS) as problem:
                raise _at_root(whole, problem, now) from None

        return either
    if op in ("==", "!="):
        return _compile_equality(expr, left, right, whole, negate=op == "!=")
    if op in FAST_ORDERING:
        return _compile_ordering(expr, left, right, whole)
    if op in ARITHMETIC:
        arithmetic = ARITHMETIC[op]
        if isinstance(expr.left, Name) and len(expr.left.path) == 1 and isinstance(
            expr.right, Literal
        ):
            # "field + 1": the field read and the constant inlined
            root, constant = field_name(expr.left.path[0]), expr.right.value

            def field_arithmetic(data: Mapping[str, Any], now: float) -> Any:
                try:
                    try:
                        value = data[root]
                    except KeyError:
                        missing_field(data, root)
                    return arithmetic(value, constant)
                except (ConditionProblem, *_PYTHON_ERRORS) as problem:
                    raise _at_root(whole, problem, now) from None

            return field_arithmetic
        return lambda data, now: arithmetic(left(data, now), right(data, now))
    raise ConditionProblem(f"unknown operator {op!r}")


def _compile_equality(expr: Binary, left: _Fn, right: _Fn, whole: _Whole, *,
                      negate: bool) -> _Fn:
    # The common shape "field == 'constant'" gets one closure with both operands inlined.
    # (Each returns a bool, so at a condition's root it is the condition: see ``whole``.)
    if isinstance(expr.left, Name) and len(expr.left.path) == 1 and isinstance(
        expr.right, Literal
    ):
        root, constant = field_name(expr.left.path[0]), _value(expr.right)
        kind = type(constant)
        # a boolean or null constant is one object: a value of its type equals it when it
        # is that object (compiled, ``==`` of two values of unknown type is a call through
        # Python's comparison protocol, about 70 instructions a robot's flag tested)
        single = constant is None or kind is bool
        # (``now`` untyped, as a conjunction's: compiled, a float parameter is unboxed on
        # entry, where only an error reads it)

        def field_equals(data: Mapping[str, Any], now: Any) -> bool:
            try:
                try:
                    value = data[root]
                except KeyError:
                    missing_field(data, root)
                if type(value) is kind:
                    if single:
                        return (value is constant) is not negate
                    return (value == constant) is not negate
                return equal(value, constant) is not negate
            except (ConditionProblem, *_PYTHON_ERRORS) as problem:
                raise _at_root(whole, problem, now) from None

        return field_equals

    if isinstance(expr.right, Literal):
        fixed = _value(expr.right)
        fixed_kind = type(fixed)

        def equals_constant(data: Mapping[str, Any], now: float) -> bool:
            try:
                a = left(data, now)
                if type(a) is fixed_kind:
                    return (a == fixed) is not negate
                return equal(a, fixed) is not negate
            except (ConditionProblem, *_PYTHON_ERRORS) as problem:
                raise _at_root(whole, problem, now) from None

        return equals_constant

    def equals(data: Mapping[str, Any], now: float) -> bool:
        try:
            a, b = left(data, now), right(data, now)
            if type(a) is type(b) and type(a) in (str, int, float, bool):
                return (a == b) is not negate
            return equal(a, b) is not negate
        except (ConditionProblem, *_PYTHON_ERRORS) as problem:
            raise _at_root(whole, problem, now) from None

    return equals


#: the ordering operators as the codes ``field_ordering`` branches on
_ORDER_CODES: Final = {"<": 0, "<=": 1, ">": 2, ">=": 3}


def _compile_ordering(expr: Binary, left: _Fn, right: _Fn, whole: _Whole) -> _Fn:
    # (At a condition's root, ``whole``, the closure is the condition: the fast paths give
    # Python bools, and ``_held`` makes :func:`ordered`'s answer one, as a condition's is.)
    op = expr.op
    fast = FAST_ORDERING[op]
    constant = expr.right.value if isinstance(expr.right, Literal) else None
    if (
        isinstance(expr.left, Name) and len(expr.left.path) == 1
        and type(constant) in (int, float)
    ):
        # "field < 3": the field read and the constant inlined, numbers compared directly.
        root = field_name(expr.left.path[0])
        # A float field is compared with the constant as two C doubles where that is
        # Python's comparison: a float constant, or an int one a double holds exactly
        # (compiled, ``fast`` is a call of ``operator.lt`` through Python's protocol)
        native = isinstance(constant, float) or (isinstance(constant, int)
                                                 and -(2 ** 53) <= constant <= 2 ** 53)
        bound = float(constant) if native and isinstance(constant, int | float) else 0.0
        order = _ORDER_CODES[op]

        def field_ordering(data: Mapping[str, Any], now: Any) -> bool:
            try:
                try:
                    value = data[root]
                except KeyError:
                    missing_field(data, root)
                kind = type(value)
                if kind is float and native:
                    held: float = value
                    if order == 0:
                        return held < bound
                    if order == 1:
                        return held <= bound
                    if order == 2:
                        return held > bound
                    return held >= bound
                if kind is int or kind is float:
                    return fast(value, constant)
                if kind is str:  # XPDL data often holds numbers as text ("3")
                    number = numeric_text(value)
                    if number is not None:
                        return fast(number, constant)
                found = ordered(value, constant, op)
                return found if whole is None else _held(found)
            except (ConditionProblem, *_PYTHON_ERRORS) as problem:
                raise _at_root(whole, problem, now) from None

        return field_ordering
    if type(constant) in (int, float):

        def ordering_constant(data: Mapping[str, Any], now: float) -> bool:
            try:
                value = left(data, now)
                kind = type(value)
                if kind is int or kind is float:
                    return fast(value, constant)
                found = ordered(value, constant, op)
                return found if whole is None else _held(found)
            except (ConditionProblem, *_PYTHON_ERRORS) as problem:
                raise _at_root(whole, problem, now) from None

        return ordering_constant

    def ordering(data: Mapping[str, Any], now: float) -> bool:
        try:
            a, b = left(data, now), right(data, now)
            ta, tb = type(a), type(b)
            if (ta is int or ta is float) and (tb is int or tb is float):
                return fast(a, b)
            if ta is str and tb is str:
                return fast(a, b)
            found = ordered(a, b, op)
            return found if whole is None else _held(found)
        except (ConditionProblem, *_PYTHON_ERRORS) as problem:
            raise _at_root(whole, problem, now) from None

    return ordering


def _at_root(whole: _Whole, problem: BaseException, now: float) -> BaseException:
    """What a closure raises for ``problem``: at an expression's root (``whole``), the
    expression's own error, naming it and its place (:func:`_fail`); below the root, the
    problem itself, for the root's closure to name."""
    return problem if whole is None else _fail(whole[0], problem, whole[1], now)


def _held(value: Any) -> bool:
    """A condition's answer for ``value`` (a comparison's, which may be NumPy's bool)."""
    return value is True or (value is not False and truthy(value))


def _compile_call(expr: Call, whole: _Whole = None) -> _Fn:
    if expr.function in TIME_HELPERS:
        helper = TIME_HELPERS[expr.function]
        if whole is None:
            return lambda data, now: helper(now)

        def time_helper(data: Mapping[str, Any], now: float) -> Any:
            try:
                return helper(now)
            except (ConditionProblem, *_PYTHON_ERRORS) as problem:
                raise _fail(whole[0], problem, whole[1], now) from None

        return time_helper
    function = IMPLEMENTATIONS.get(expr.function)
    if function is None:
        raise ConditionProblem(f"unknown function {expr.function!r}")
    args = tuple(_compile(arg) for arg in expr.args)
    if len(args) == 1:
        (only,) = args
        return lambda data, now: function(only(data, now))
    if len(args) == 2:
        first, second = args
        return lambda data, now: function(first(data, now), second(data, now))
    return lambda data, now: function(*[arg(data, now) for arg in args])
