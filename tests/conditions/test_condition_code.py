"""Conditions written out as one Python function (opspec.engine.condition_code) mean exactly
what the closures mean: the same values of the same types, the same errors with the same
messages, the same order of evaluation, for every node kind, odd field names and literals,
and random trees; and nothing the spec wrote is spliced into the generated source."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from opspec.engine import conditions
from opspec.engine.condition_code import MAX_NESTING, TIME_SOURCE, generate
from opspec.engine.condition_values import TIME_HELPERS
from opspec.errors import ExecutionError, SourceLocation
from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary
from opspec.xpdl.conditions import parse_expression

from .test_condition_properties import (
    SETTINGS,
    field_names,
    field_values,
    outcome,
    small_literals,
    trees,
)

pytestmark = pytest.mark.skipif(
    conditions.COMPILED, reason="the engine runs compiled: conditions stay native closures")

WHERE = SourceLocation("spec.xpdl", 12, 5)


def both(expr: Expression, *, condition: bool) -> tuple[Callable[..., Any], Callable[..., Any]]:
    """(the generated function, the closures) of ``expr``, both located at WHERE."""
    make = conditions.compile_condition if condition else conditions.compile_expression
    written = make(expr, location=WHERE)
    assert written.__doc__ is not None and written.__doc__.startswith("def evaluate(")
    saved = conditions.COMPILED
    conditions.COMPILED = True          # type: ignore[misc]
    try:
        nested = make(expr, location=WHERE)
    finally:
        conditions.COMPILED = saved     # type: ignore[misc]
    assert nested.__doc__ is None or not nested.__doc__.startswith("def evaluate(")
    return written, nested


def result(run: Callable[[], Any]) -> tuple[str, Any, Any]:
    """What a call gives: its value and type, or its error's message, location and time."""
    try:
        value = run()
    except ExecutionError as error:
        return "error", (error.message, error.hint), (error.location, error.sim_time)
    return "value", value, type(value)


def agree(expr: Expression, data: Any, now: float = 0.0) -> tuple[str, Any, Any]:
    for condition in (True, False):
        written, nested = both(expr, condition=condition)
        got = result(lambda fn=written: fn(data, now))  # type: ignore[misc]
        want = result(lambda fn=nested: fn(data, now))  # type: ignore[misc]
        if want[0] == "value" and isinstance(want[1], float) and math.isnan(want[1]):
            assert got[0] == "value" and math.isnan(got[1]), (got, want)
        else:
            assert got == want, (expr, data, got, want)
    return got


DATA = {"n": 2, "x": 2.5, "s": "abc", "t": "3", "flag": True, "off": False, "none": None,
        "rec": {"a": {"b": 7}}, "items": [1, 2, 3], "big": 2 ** 1023, "word": "TRUE"}

CASES = [
    # fields, dotted names, missing fields and members
    "n", "rec.a.b", "items.length", "s.length", "missing", "rec.zz", "n.b",
    # equality, each same-type fast path and each mixed rule
    "n == 2", "n != 2", "x == 2.5", "s == 'abc'", "s != 'abd'", "t == 3", "t == 3.0",
    "flag == true", "off == false", "word == true", "none == null", "n == null", "n == s",
    "n == x", "s == t", "rec == rec", "items != items", "flag == 1",
    # ordering: numbers, texts, text holding numbers, and the pairs that have no order
    "n < 3", "x >= 2.5", "t < 10", "t > 2.5", "s < 'abd'", "'10' < '9'", "n < x", "flag < 2",
    "s < 3", "none < 1", "n < none", "n <= s", "rec > 1",
    # arithmetic: in line for numbers, by the rules for the rest, and the integer bound
    "n + 1", "x - 1", "n * 3", "s + 1", "1 + s", "t + 1", "t - 1", "t * 2", "flag + flag",
    "n / 4", "n / 0", "n % 0", "-7 % 3", "x % 2", "items + items", "items * 2", "s * 2",
    "big * 2", "big + big", "big - 1", "-n", "-s", "-t", "none + 1",
    # logic: short-circuit (the right side's error never happens), truthiness of each kind
    "n < 3 && s == 'abc'", "off && missing", "flag || missing", "!flag", "!s", "!'false'",
    "!none", "!items", "n && x", "none || s", "missing && flag", "'0' || ''",
    # functions and the time helpers
    "abs(-n)", "max(n, x, 1)", "min(items)", "round(x)", "len(s)", "contains(items, 2)",
    "lower(word)", "str(x)", "int(t)", "float(s)", "hour()", "day()", "now()",
    "time_of_day()", "hour() >= 8 && hour() < 12", "max(items, 9)", "round(s)",
]


@pytest.mark.parametrize("text", CASES)
def test_the_generated_function_agrees_with_the_closures(text: str) -> None:
    for now in (0.0, 30_000.5, 86_399.99, 5 * 86_400 + 13 * 3600.0):
        agree(parse_expression(text), DATA, now)


def test_a_missing_field_names_the_field_the_condition_and_its_place() -> None:
    kind, (message, hint), (where, when) = agree(parse_expression("hour < 10"), {"x": 1}, 7.0)
    assert kind == "error"
    assert message == ("cannot evaluate condition `hour < 10`: data field 'hour' does not "
                       "exist (fields: x)")
    assert "declare the data field" in hint
    assert (where, when) == (WHERE, 7.0)


ODD = ["it's", 'say "hi"', "back\\slash", "new\nline", "é中🙂", "data", "now", "problem",
       "v1", "K20", "TRUTHY", "__import__", "'); import os; ('", "\\'", '"""', "{0}"]


@pytest.mark.parametrize("odd", ODD)
def test_odd_field_names_and_texts_evaluate_as_before_and_never_reach_the_source(
        odd: str) -> None:
    data = {odd: odd, "plain": odd, "nested": {odd: 1}}
    exprs = [
        Binary("==", Name((odd,)), Literal(odd)),
        Binary("!=", Name(("plain",)), Literal(odd + "x")),
        Binary("<", Literal(odd), Name((odd,))),
        Binary("+", Name((odd,)), Literal(odd)),
        Binary("and", Name((odd,)), Binary("==", Name(("nested", odd)), Literal(1))),
        Call("contains", (Name((odd,)), Literal(odd[:1]))),
        Name(("missing" + odd,)),
    ]
    for expr in exprs:
        agree(expr, data)
        written = conditions.compile_condition(expr, location=WHERE)
        assert written.__doc__ is not None
        if odd not in ("data", "now", "problem", "v1", "K20", "TRUTHY", "{0}"):
            assert odd not in written.__doc__
    assert conditions.compile_condition(exprs[0])(data, 0.0) is True
    assert conditions.compile_expression(exprs[3])(data, 0.0) == odd + odd


def test_the_time_helpers_in_line_are_the_helpers() -> None:
    for now in (0.0, 0.4, 3599.999, 3600.0, 43_200.5, 86_399.999, 86_400.0, 1e9 + 0.3):
        for name in TIME_SOURCE:
            got = conditions.compile_expression(Call(name, ()))({}, now)
            want = TIME_HELPERS[name](now)
            assert got == want and type(got) is type(want), (name, now, got, want)


def test_a_tree_nested_too_deep_to_write_out_keeps_its_closures() -> None:
    chain: Expression = Binary(">", Name(("n",)), Literal(0))
    for _ in range(MAX_NESTING + 5):    # a right-nested && chain: each level one `if` deeper
        chain = Binary("and", Literal(True), chain)
    assert generate(chain, lambda problem, now: ValueError(), condition=True) is None
    holds = conditions.compile_condition(chain)
    assert holds({"n": 1}, 0.0) is True and holds({"n": 0}, 0.0) is False
    with pytest.raises(ExecutionError, match="data field 'n' does not exist"):
        holds({}, 0.0)


def test_evaluation_order_is_left_to_right_and_short_circuits() -> None:
    class Recording(dict[str, Any]):
        def __init__(self, *args: Any) -> None:
            super().__init__(*args)
            self.read: list[str] = []

        def __getitem__(self, key: str) -> Any:
            self.read.append(key)
            return super().__getitem__(key)

    expr = parse_expression("a + b < c || (d && e) || max(f, g) == 1")
    values = {"a": 1, "b": 1, "c": 1, "d": 0, "e": 1, "f": 1, "g": 0}
    for condition in (True, False):
        for fn in both(expr, condition=condition):
            data = Recording(values)
            fn(data, 0.0)
            assert data.read == ["a", "b", "c", "d", "f", "g"]


@SETTINGS
@given(
    trees(st.one_of(small_literals, field_names,
                    st.just(Name(("r", "k"))), st.just(Name(("a", "length"))))),
    st.fixed_dictionaries({"a": field_values, "b": field_values, "c": field_values,
                           "r": st.fixed_dictionaries({"k": field_values})}),
    st.floats(min_value=0, max_value=10 * 86400),
)
def test_random_trees_agree_with_the_closures(expr: Expression, data: dict[str, Any],
                                              now: float) -> None:
    for make in (conditions.compile_condition, conditions.compile_expression):
        written = outcome(lambda make=make: make(expr)(data, now))  # type: ignore[misc]
        saved = conditions.COMPILED
        conditions.COMPILED = True      # type: ignore[misc]
        try:
            nested = outcome(lambda make=make: make(expr)(data, now))  # type: ignore[misc]
        finally:
            conditions.COMPILED = saved  # type: ignore[misc]
        assert written[0] == nested[0], (written, nested)
        a, b = written[1], nested[1]
        if written[0] == "value":
            assert type(a) is type(b)
            assert a == b or (isinstance(a, float) and math.isnan(a) and math.isnan(b))
        else:
            assert a == b


def test_unary_and_call_nodes_of_every_kind_are_written_out() -> None:
    expr = Unary("not", Binary("or", Unary("neg", Name(("n",))),
                               Call("str", (Call("now", ()),))))
    written, nested = both(expr, condition=False)
    assert "AS_NUMBER" in written.__doc__ and "now" in written.__doc__
    assert written({"n": 0}, 1.5) is nested({"n": 0}, 1.5) is False


def test_only_a_constant_expression_tells_its_value_to_the_plans() -> None:
    for value in (None, True, 0, 2.5, "it's \\ é"):
        fn = conditions.compile_expression(Literal(value))
        assert conditions.constant_value(fn) == (value,) and fn({}, 0.0) is value
    for text in ("n", "n + 1", "hour()"):
        assert conditions.constant_value(conditions.compile_expression(
            parse_expression(text))) is None
    assert conditions.constant_value(conditions.compile_condition(Literal(True))) is None
