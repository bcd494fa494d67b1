"""Conditions evaluate with the documented, JavaScript-like but predictable semantics.

Every case runs twice: through the tree walker (``evaluate``) and through the compiled closures
(``compile_expression``); both must agree.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import pytest

from opspec.engine.conditions import (
    compile_condition,
    compile_expression,
    evaluate,
    evaluate_condition,
    truthy,
)
from opspec.errors import ExecutionError, SourceLocation
from opspec.model.expressions import Binary, Literal, Name
from opspec.xpdl.conditions import parse_expression

DATA: dict[str, Any] = {
    "status": "approved",
    "n": 2,
    "count_text": "3",
    "price": 2.5,
    "done": False,
    "flag_text": "TRUE",
    "nothing": None,
    "order": {"total": 12.5, "lines": [1, 2, 3], "customer": {"name": "Ada"}},
    "tags": ["a", "b"],
    "empty": "",
}

Runner = Callable[[str, Mapping[str, Any]], Any]


def walk(text: str, data: Mapping[str, Any]) -> Any:
    return evaluate(parse_expression(text), data, clock=lambda: 0.0)


def compiled(text: str, data: Mapping[str, Any]) -> Any:
    return compile_expression(parse_expression(text))(data, 0.0)


@pytest.fixture(params=[walk, compiled], ids=["walker", "compiled"])
def run(request: pytest.FixtureRequest) -> Runner:
    runner: Runner = request.param
    return runner


CASES = [
    # (id, text, expected value)
    ("string-equality", 'status == "approved"', True),
    ("string-equality-is-case-sensitive", 'status == "Approved"', False),
    ("number-equals-numeric-text", "count_text == 3", True),
    ("numeric-text-equals-float", '"3.0" == 3', True),
    ("text-without-number-equals-no-number", '"abc" == 0', False),
    ("bool-equals-text-ignoring-case", "flag_text == true", True),
    ("bool-vs-other-text-is-unequal", '"yes" == true', False),
    ("true-equals-one", "true == 1", True),
    ("null-equals-only-null", "nothing == null", True),
    ("null-is-not-zero", "nothing == 0", False),
    ("null-is-not-empty-text", 'nothing == ""', False),
    ("not-equals", 'status != "x"', True),
    ("number-less-than-numeric-text", "n < count_text", True),
    ("numeric-text-greater-than-number", "count_text > 2.5", True),
    ("texts-order-as-text", '"10" < "9"', True),
    ("range", "0 <= n <= 5", True),
    ("range-outside", "3 <= n <= 5", False),
    ("and-returns-boolean", "n && status", True),
    ("or-returns-boolean", "0 || done", False),
    ("and-short-circuits", "done && missing_field", False),
    ("or-short-circuits", "true || missing_field", True),
    ("bang-not", "!done", True),
    ("not-of-false-text", '!"false"', True),
    ("plus-adds-numbers", "n + 1", 3),
    ("plus-concatenates-text", 'status + "!"', "approved!"),
    ("plus-concatenates-numeric-text-like-js", "count_text + 1", "31"),
    ("minus-converts-numeric-text", "count_text - 1", 2),
    ("divide-gives-float", "7 / 2", 3.5),
    ("remainder-sign-of-dividend", "-7 % 3", -1),
    ("remainder-float", "7.5 % 2", 1.5),
    ("negation", "-price", -2.5),
    ("dotted-record-member", "order.total * 2", 25.0),
    ("nested-record-member", 'order.customer.name == "Ada"', True),
    ("length-pseudo-member", "order.lines.length", 3),
    ("abs", "abs(-3)", 3),
    ("min-numbers", "min(3, 1, 2)", 1),
    ("max-of-list", "max(order.lines)", 3),
    ("round-half-away-from-zero", "round(-2.5)", -3),
    ("round-digits", "round(2.675, 2)", 2.68),
    ("floor", "floor(2.7)", 2),
    ("ceil", "ceil(2.1)", 3),
    ("len-text", "len(status)", 8),
    ("lower", 'lower("AbC")', "abc"),
    ("upper", 'upper("AbC")', "ABC"),
    ("contains-text", 'contains(status, "prov")', True),
    ("contains-list", 'contains(tags, "b")', True),
    ("startswith", 'startswith(status, "app")', True),
    ("endswith", 'endswith(status, "ved")', True),
    ("indexOf-found", "status.indexOf('p') != -1", True),
    ("indexOf-missing", "status.indexOf('z')", -1),
    ("compareTo-equal-bool-text", 'done.compareTo(Boolean.valueOf("false")) == 0', True),
    ("compareTo-order", '"a".compareTo("b")', -1),
    ("str-of-integral-float", "str(2.0)", "2"),
    ("str-of-bool", "str(true)", "true"),
    ("str-of-null", "str(null)", "null"),
    ("int-truncates", 'int("-3.9")', -3),
    ("float-of-text", 'float("2.5")', 2.5),
    ("bool-of-false-text", 'bool("FALSE")', False),
    ("equalsIgnoreCase", 'status.equalsIgnoreCase("APPROVED")', True),
]


@pytest.mark.parametrize(("text", "expected"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_conditions_follow_the_documented_semantics(run: Runner, text: str, expected: Any) -> None:
    result = run(text, DATA)
    assert result == expected
    assert type(result) is type(expected)


TRUTHY = [
    (None, False), (False, False), (True, True), (0, False), (0.0, False), (float("nan"), False),
    (2, True), (-0.5, True), ("", False), ("false", False), (" FALSE ", False), ("0", False),
    ("no", True), ("x", True), ([], False), ([0], True), ({}, False), ({"a": 1}, True),
]


@pytest.mark.parametrize(("value", "expected"), TRUTHY, ids=[repr(v) for v, _ in TRUTHY])
def test_truthiness_rules(value: Any, expected: bool) -> None:
    assert truthy(value) is expected


ERRORS = [
    # (id, text, message fragment)
    ("missing-field", "missing == 1",
     ("data field 'missing' does not exist (fields: count_text, done, empty, flag_text, n, "
      "nothing, order, price, status, tags)")),
    ("missing-record-member", "order.nope",
     "record 'order' has no member 'nope' (members: customer, lines, total)"),
    ("member-of-text", "status.nope", "'status' is text, so it has no member 'nope'"),
    ("division-by-zero", "n / 0", "division by zero"),
    ("remainder-by-zero", "n % 0", "remainder of a division by zero"),
    ("order-number-and-word", 'n < "abc"',
     "cannot compare 2 (number) < 'abc' (text): abc is not a number"),
    ("order-with-null", "nothing > 1", "cannot compare null > 1 (number)"),
    ("arithmetic-on-word", 'status * 2', "'*' needs a number, got 'approved' (text)"),
    ("len-of-number", "len(n)", "len() needs a text, list or record"),
]


@pytest.mark.parametrize(("text", "fragment"), [e[1:] for e in ERRORS], ids=[e[0] for e in ERRORS])
def test_evaluation_problems_are_execution_errors_quoting_the_condition(
    run: Runner, text: str, fragment: str
) -> None:
    with pytest.raises(ExecutionError) as caught:
        run(text, DATA)
    message = str(caught.value)
    assert fragment in message
    assert message.startswith("cannot evaluate condition `")


def test_missing_field_error_carries_location_time_and_a_fix_hint() -> None:
    where = SourceLocation("specs/pump.xpdl", 40)
    check = compile_expression(parse_expression("dose > 3"), location=where)
    with pytest.raises(ExecutionError, match=r"^specs/pump\.xpdl:40: .*'dose' does not exist") as caught:
        check({"n": 1}, 12.0)
    assert caught.value.sim_time == 12.0
    assert "declare the data field" in caught.value.hint


CLOCK = [
    # simulated time 2 days + 08:30:15 -> (function, value)
    ("now", 2 * 86400 + 8 * 3600 + 30 * 60 + 15.0),
    ("time_of_day", 8 * 3600 + 30 * 60 + 15.0),
    ("hour", 8),
    ("day", 2),
]


@pytest.mark.parametrize(("function", "expected"), CLOCK, ids=[c[0] for c in CLOCK])
def test_time_helpers_read_the_injected_simulation_clock(function: str, expected: Any) -> None:
    now = 2 * 86400 + 8 * 3600 + 30 * 60 + 15.0
    expr = parse_expression(f"{function}()")
    assert evaluate(expr, {}, clock=lambda: now) == expected
    assert compile_expression(expr)({}, now) == expected


def test_morning_condition_switches_with_simulated_time() -> None:
    morning = compile_condition(parse_expression("hour() >= 8 && hour() < 12"))
    assert not morning({}, 7 * 3600.0)
    assert morning({}, 8 * 3600.0)
    assert not morning({}, 86400 + 13 * 3600.0)
    assert morning({}, 86400 + 9 * 3600.0)


def test_time_helpers_without_a_clock_are_an_error_not_the_wall_clock() -> None:
    with pytest.raises(ExecutionError, match=r"now\(\) needs the simulation clock"):
        evaluate(parse_expression("now() > 0"), {})


def test_evaluate_condition_applies_truthiness() -> None:
    assert evaluate_condition(parse_expression("status"), {"status": "false"}) is False
    assert evaluate_condition(parse_expression("status"), {"status": "ok"}) is True


def test_no_condition_compiles_to_always_true() -> None:
    assert compile_condition(None)({}, 0.0) is True


def test_compiled_condition_returns_booleans() -> None:
    check = compile_condition(parse_expression("n"))
    assert check({"n": 5}, 0.0) is True
    assert check({"n": 0}, 0.0) is False


def test_hand_built_tree_with_unknown_operator_is_an_execution_error() -> None:
    bogus = Binary("**", Name(("a",)), Literal(2))
    with pytest.raises(ExecutionError, match="unknown operator"):
        compile_expression(bogus)
    with pytest.raises(ExecutionError, match="unknown operator"):
        evaluate(bogus, {"a": 1})


def test_data_can_be_any_mapping() -> None:
    from types import MappingProxyType

    data = MappingProxyType({"a": 1})
    assert compile_condition(parse_expression("a == 1"))(data, 0.0) is True
    with pytest.raises(ExecutionError, match="'b' does not exist"):
        compile_condition(parse_expression("b == 1"))(data, 0.0)


@pytest.mark.parametrize(("text", "expected"), [
    ("a + b", (11.0, 22.0)), ("b - a", (9.0, 18.0)), ("2 * a", (2.0, 4.0)),
    ("a * 2", (2.0, 4.0)), ("b / 10", (1.0, 2.0)), ("1 * a + 2 * b", (21.0, 42.0)),
])
def test_arithmetic_on_arrays_is_element_wise(run: Runner, text: str,
                                              expected: tuple[float, ...]) -> None:
    assert run(text, {"a": (1.0, 2.0), "b": [10.0, 20.0]}) == expected


@pytest.mark.parametrize("text", ["a + c", "a + 1", "a / a"])
def test_array_arithmetic_that_has_no_meaning_is_an_error(run: Runner, text: str) -> None:
    with pytest.raises(ExecutionError):
        run(text, {"a": (1.0, 2.0), "c": (1.0, 2.0, 3.0)})
