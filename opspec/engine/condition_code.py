"""A condition or expression written out as the source of one Python function.

From source every closure :func:`opspec.engine.conditions.compile_expression` nests is a
Python call (about 0.6k instructions each): ``hour < 10`` is two, ``alarms + 1`` five
(``run``, the ``+``, its constant, ``_add``, ``bounded``). Here the same tree becomes one
function whose body does each node's work in line — a field read, the same-type fast paths
of ``==`` and ``<``, the number case of ``+ - *``, the time helpers, ``&&``/``||``/``!``
short-circuiting on booleans — and calls the rules of :mod:`opspec.engine.condition_values`
for everything else, exactly where the closures call them. Its meaning is theirs: the same
values, the same errors (an :class:`~opspec.errors.ExecutionError` quoting the condition at
its location), the same order of evaluation (``tests/conditions/test_condition_code.py``
holds every node kind, odd field names and literals, and random trees to the closures).

Safe to ``exec``: the source is the engine's own. Nothing the spec wrote (field names,
texts, numbers) is in it; each is an object bound by name in the function's globals
(:meth:`_Writer.bind`), and operators come from fixed tables here.

Only from source (:mod:`opspec.engine.conditions` decides): compiled by mypyc the closures
are native code and this interpreted function would be slower.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, Final

from opspec.engine.condition_values import (
    ARITHMETIC,
    FAST_ORDERING,
    IMPLEMENTATIONS,
    MAX_INT_BITS,
    NUMBERS,
    TIME_HELPERS,
    ConditionProblem,
    as_number,
    bounded,
    equal,
    lookup,
    missing_field,
    ordered,
    truthy,
)
from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary

__all__ = ["MAX_NESTING", "TIME_SOURCE", "generate"]

#: Nested ``if`` levels a generated function may have (``&&``/``||`` right operands); a
#: deeper tree keeps its closures (Python's parser stops at 100 indentation levels).
MAX_NESTING: Final = 40

#: The time helpers in line; each is ``TIME_HELPERS[name](now)`` (tested to agree).
TIME_SOURCE: Final = {
    "now": "now",
    "time_of_day": "now % DAY",
    "hour": "int((now % DAY) // 3600)",
    "day": "int(now // DAY)",
}
assert set(TIME_SOURCE) == set(TIME_HELPERS), "time helpers and their source disagree"

_ORDERING: Final = {"<": "<", "<=": "<=", ">": ">", ">=": ">="}
_INLINE_ARITHMETIC: Final = {"+": "+", "-": "-", "*": "*"}
_ERRORS: Final = (ConditionProblem, TypeError, ValueError, ArithmeticError)
_MAX_INT: Final = 1 << MAX_INT_BITS

Fail = Callable[[BaseException, float], Exception]


class _TooDeep(Exception):
    """The tree nests more than :data:`MAX_NESTING` levels: keep the closures."""


def generate(expr: Expression, fail: Fail, *, condition: bool
             ) -> Callable[[Mapping[str, Any], float], Any] | None:
    """``f(data, now)`` for ``expr``: its truth under the truthiness rules if ``condition``,
    else its value; ``fail(problem, now)`` makes the error a failed evaluation raises.
    ``None`` where the tree is too deep to write out (the caller keeps its closures)."""
    writer = _Writer()
    body: list[str] = []
    try:
        result = writer.value(expr, body, 2)
    except (_TooDeep, RecursionError):
        return None
    space = writer.names
    space["FAIL"] = fail
    space["ERRORS"] = _ERRORS
    ending = (f"    return {_truth(result)}" if condition and not _boolean(expr)
              else f"    return {result}")
    lines = ["def evaluate(data, now):", "    try:", *body,
             "    except ERRORS as problem:",
             "        raise FAIL(problem, now) from None",
             ending]
    source = "\n".join(lines) + "\n"
    try:
        code = compile(source, "<condition>", "exec")
    except (SyntaxError, RecursionError, MemoryError):  # nesting past the parser's limits
        return None
    exec(code, space)  # noqa: S102 - the engine's own source, see the module's docstring
    function: Callable[[Mapping[str, Any], float], Any] = space["evaluate"]
    function.__doc__ = source               # what it runs, for whoever debugs it
    return function


class _Writer:
    """Writes one function's body: each node's statements, its value in a local."""

    def __init__(self) -> None:
        self.locals = 0
        self.names: dict[str, Any] = {
            "__builtins__": {}, "type": type, "int": int, "float": float, "str": str,
            "bool": bool, "KeyError": KeyError, "DAY": 86_400.0, "MAXI": _MAX_INT,
            "NUMBERS": NUMBERS, "SIMPLE": (str, int, float, bool),
            "TRUTHY": truthy, "EQUAL": equal, "ORDERED": ordered, "MISSING": missing_field,
            "LOOKUP": lookup, "AS_NUMBER": as_number, "BOUNDED": bounded}

    def bind(self, value: Any) -> str:
        """The global name ``value`` is bound to in the function (its text is never
        written into the source)."""
        key = f"K{len(self.names)}"
        self.names[key] = value
        return key

    def local(self) -> str:
        self.locals += 1
        return f"v{self.locals}"

    def value(self, expr: Expression, out: list[str], depth: int) -> str:
        """Append the statements computing ``expr`` at ``depth``; the name of its value."""
        if depth > MAX_NESTING:
            raise _TooDeep
        if isinstance(expr, Literal):
            return self.bind(expr.value)
        pad = "    " * depth
        if isinstance(expr, Name):
            v = self.local()
            if len(expr.path) == 1:         # conditions._compile_name's ``field``
                key = self.bind(expr.path[0])
                out += [f"{pad}try:", f"{pad}    {v} = data[{key}]",
                        f"{pad}except KeyError:", f"{pad}    MISSING(data, {key})"]
            else:
                out.append(f"{pad}{v} = LOOKUP(data, {self.bind(expr.path)})")
            return v
        if isinstance(expr, Unary):
            operand = self.value(expr.operand, out, depth)
            v = self.local()
            if expr.op == "not":
                out.append(f"{pad}{v} = not ({_truth(operand)})")
            elif expr.op == "neg":
                what = self.bind("'-'")
                out.append(f"{pad}{v} = -AS_NUMBER({operand}, {what})")
            else:
                raise ConditionProblem(f"unknown operator {expr.op!r}")
            return v
        if isinstance(expr, Binary):
            return self.binary(expr, out, depth)
        if isinstance(expr, Call):
            return self.call(expr, out, depth)
        raise ConditionProblem(f"not an expression node: {expr!r}")

    def binary(self, expr: Binary, out: list[str], depth: int) -> str:
        op = expr.op
        pad = "    " * depth
        left = self.value(expr.left, out, depth)
        v = self.local()
        if op in ("and", "or"):             # short-circuit, a boolean either way
            inner: list[str] = []
            right = self.value(expr.right, inner, depth + 1)
            test = _truth(left) if op == "and" else f"not ({_truth(left)})"
            out += [f"{pad}if {test}:", *inner,
                    f"{pad}    {v} = {_truth(right)}",
                    f"{pad}else:", f"{pad}    {v} = {'False' if op == 'and' else 'True'}"]
            return v
        right = self.value(expr.right, out, depth)
        if op in ("==", "!="):
            out.append(f"{pad}{v} = {self.equality(expr, left, right, op == '!=')}")
        elif op in FAST_ORDERING:
            out += self.ordering(expr, left, right, v, pad)
        elif op in _INLINE_ARITHMETIC:
            out += self.arithmetic(expr, left, right, v, pad)
        elif op in ARITHMETIC:
            out.append(f"{pad}{v} = {self.bind(ARITHMETIC[op])}({left}, {right})")
        else:
            raise ConditionProblem(f"unknown operator {op!r}")
        return v

    def equality(self, expr: Binary, left: str, right: str, negate: bool) -> str:
        """``conditions._compile_equality``: same-type values compare with ``==``."""
        if isinstance(expr.right, Literal):
            kind = self.bind(type(expr.right.value))
            same, other = f"{left} == {right}", f"EQUAL({left}, {right})"
            if negate:
                same, other = f"not ({same})", f"not {other}"
            return f"({same}) if type({left}) is {kind} else {other}"
        same, other = f"{left} == {right}", f"EQUAL({left}, {right})"
        if negate:
            same, other = f"not ({same})", f"not {other}"
        return (f"({same}) if type({left}) is type({right}) and type({left}) in SIMPLE "
                f"else {other}")

    def ordering(self, expr: Binary, left: str, right: str, v: str, pad: str) -> list[str]:
        """``conditions._compile_ordering``: numbers, and two texts, compare directly; every
        other pair by :func:`ordered` (for a text against a number constant it does what
        ``field_ordering``'s text branch does: the text's number, else the same error)."""
        op = _ORDERING[expr.op]
        how = self.bind(expr.op)
        constant = expr.right.value if isinstance(expr.right, Literal) else None
        if type(constant) in (int, float):
            return [f"{pad}{v} = type({left})",
                    (f"{pad}{v} = {left} {op} {right} if {v} is int or {v} is float "
                     f"else ORDERED({left}, {right}, {how})")]
        t = self.local()
        return [f"{pad}{v} = type({left})", f"{pad}{t} = type({right})",
                (f"{pad}if (({v} is int or {v} is float) and ({t} is int or {t} is float)) "
                 f"or ({v} is str and {t} is str):"),
                f"{pad}    {v} = {left} {op} {right}",
                f"{pad}else:",
                f"{pad}    {v} = ORDERED({left}, {right}, {how})"]

    def arithmetic(self, expr: Binary, left: str, right: str, v: str, pad: str) -> list[str]:
        """``+ - *``: two numbers in line (``condition_values._add``'s first branch and its
        bound), anything else by the rule's function."""
        op = expr.op
        tests = [f"type({side}) in NUMBERS" for side, node in ((left, expr.left),
                                                                (right, expr.right))
                 if not (isinstance(node, Literal) and type(node.value) in NUMBERS)]
        what = self.bind(f"'{op}'")
        return [f"{pad}if {' and '.join(tests) or 'True'}:",
                f"{pad}    {v} = {left} {_INLINE_ARITHMETIC[op]} {right}",
                f"{pad}    if type({v}) is int and not -MAXI < {v} < MAXI:",
                f"{pad}        BOUNDED({v}, {what})",
                f"{pad}else:",
                f"{pad}    {v} = {self.bind(ARITHMETIC[op])}({left}, {right})"]

    def call(self, expr: Call, out: list[str], depth: int) -> str:
        pad = "    " * depth
        if expr.function in TIME_SOURCE:
            v = self.local()
            out.append(f"{pad}{v} = {TIME_SOURCE[expr.function]}")
            return v
        function = IMPLEMENTATIONS.get(expr.function)
        if function is None:
            raise ConditionProblem(f"unknown function {expr.function!r}")
        args = [self.value(arg, out, depth) for arg in expr.args]
        v = self.local()
        out.append(f"{pad}{v} = {self.bind(function)}({', '.join(args)})")
        return v


def _boolean(expr: Expression) -> bool:
    """Whether ``expr``'s value is always a boolean (its truth is itself): the logic
    operators, and the comparisons (same-type ``==`` and ``<`` of texts and numbers give
    one, as do :func:`equal` and :func:`ordered`)."""
    if isinstance(expr, Unary):
        return expr.op == "not"
    return isinstance(expr, Binary) and (expr.op in ("and", "or", "==", "!=")
                                         or expr.op in FAST_ORDERING)


def _truth(name: str) -> str:
    """``truthy(name)``, with booleans answered without a call."""
    return f"{name} is True or ({name} is not False and TRUTHY({name}))"
