"""A condition whose root is ``&&`` or ``||`` is that closure itself (no wrapper around it,
``conditions.compile_condition``): the same values, booleans and messages as the tree
walker's, whichever operand fails."""

from __future__ import annotations

import numpy as np
import pytest

from opspec.engine.conditions import compile_condition, evaluate_condition
from opspec.errors import ExecutionError, SourceLocation
from opspec.xpdl.conditions import parse_condition

WHERE = SourceLocation("spec.xpdl", 7)

CONDITIONS = ["hour < 10 && fault == \"\"", "hour > 3 || slot == 2", "fault && hour < 10",
              "hour + 1 < 10 || fault", "bump == true && escaping == false",
              "!(hour < 3) && slot", "hour() > 1 || alarms > 1", "missing == 1 && hour < 10",
              "hour < 10 || missing == 1"]
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
def test_conjunctions_answer_as_the_walker(text: str) -> None:
    expr = parse_condition(text)
    held = compile_condition(expr, location=WHERE)
    outcomes = set()
    for data in DATA:
        got = _outcome(held, data, 36000.0)
        want = _outcome(lambda d, n: evaluate_condition(expr, d, clock=lambda: n,
                                                        location=WHERE), data, 36000.0)
        assert got == want, (text, data)
        if got[0] == "value":
            assert type(got[1]) is bool
        outcomes.add(got[0])
    assert outcomes                             # (each text answered for every data)
