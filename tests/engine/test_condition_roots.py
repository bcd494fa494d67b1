"""A condition's or expression's root closure answers for its own errors (no wrapper around
it; a comparison, a field, a time helper, "field op constant", a conjunction): the same
values, booleans and messages as the tree walker's."""

from __future__ import annotations

import numpy as np
import pytest

from opspec.engine.conditions import (
    COMPILED,
    compile_condition,
    compile_expression,
    evaluate,
    evaluate_condition,
)
from opspec.errors import ExecutionError, SourceLocation
from opspec.xpdl.conditions import parse_condition

WHERE = SourceLocation("spec.xpdl", 3)

CONDITIONS = ["hour < 10", "hour >= 10.5", "fault != \"\"", "fault == \"x\"", "hour < slot",
              "hour + 1 < 10", "hour == slot", "hour > \"9\"", "!(hour < 3)",
              # a conjunction at the root is its own closure too, whichever operand fails
              "hour < 10 && fault == \"\"", "hour > 3 || slot == 2", "fault && hour < 10",
              "hour + 1 < 10 || fault", "bump == true && escaping == false",
              "!(hour < 3) && slot", "hour() > 1 || alarms > 1", "missing == 1 && hour < 10",
              "hour < 10 || missing == 1"]
EXPRESSIONS = ["hour", "hour + 1", "alarms * 2", "hour()", "slot - 1", "fault + 1"]
DATA = [
    {"hour": 9, "fault": "", "slot": 3, "alarms": 1, "bump": True, "escaping": False},
    {"hour": 12.5, "fault": "x", "slot": "12.5", "alarms": 2, "bump": False, "escaping": True},
    {"hour": "7", "fault": "y", "slot": 2, "alarms": "3", "bump": True, "escaping": True},
    {"hour": np.float64(9.0), "fault": "", "slot": np.float64(9.0), "alarms": 1,
     "bump": np.bool_(True), "escaping": np.bool_(False)},
    {"hour": "abc", "fault": None, "slot": None, "alarms": None, "bump": None},
    {"fault": ""},
]


def _outcome(fn, *args):
    try:
        return ("value", fn(*args))
    except ExecutionError as error:
        return ("error", str(error))


@pytest.mark.parametrize("text", CONDITIONS)
def test_conditions_answer_as_the_walker(text: str) -> None:
    expr = parse_condition(text)
    held = compile_condition(expr, location=WHERE)
    for data in DATA:
        got = _outcome(held, data, 36000.0)
        want = _outcome(lambda d, n: evaluate_condition(expr, d, clock=lambda: n,
                                                        location=WHERE), data, 36000.0)
        assert got == want, (text, data)
        if got[0] == "value":
            assert type(got[1]) is bool         # a condition's answer, never NumPy's bool


@pytest.mark.parametrize("text", EXPRESSIONS)
def test_expressions_answer_as_the_walker(text: str) -> None:
    expr = parse_condition(text)
    value = compile_expression(expr, location=WHERE)
    for data in DATA:
        got = _outcome(value, data, 36000.0)
        want = _outcome(lambda d, n: evaluate(expr, d, clock=lambda: n, location=WHERE),
                        data, 36000.0)
        assert got == want, (text, data)
        if got[0] == "value":
            assert type(got[1]) is type(want[1])


@pytest.mark.skipif(COMPILED, reason="compiled closures are not Python functions")
def test_a_comparison_or_a_field_is_its_own_root() -> None:
    # (from source each closure level is a Python call: the root has no wrapper around it)
    assert compile_condition(parse_condition("hour < 10")).__name__ == "field_ordering"
    assert compile_condition(parse_condition("fault != \"\"")).__name__ == "field_equals"
    assert compile_expression(parse_condition("alarms + 1")).__name__ == "field_arithmetic"
    assert compile_expression(parse_condition("hour")).__name__ == "field"
    assert compile_expression(parse_condition("hour()")).__name__ == "time_helper"
    assert compile_expression(parse_condition("hour * slot")).__name__ == "run"
