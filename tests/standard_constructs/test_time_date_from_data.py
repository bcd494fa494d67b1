"""A timeDate read from a data field that holds an ISO date fires at that date."""

from __future__ import annotations

import pytest

from opspec.errors import OpspecError

from .conftest import completed, kinds, run


@pytest.mark.parametrize(("due", "fires"), [
    (None, 7200.0),                              # the initial value, 02:00 on day 1
    ("2026-03-01T05:30:00", 19800.0),            # set before the run: 05:30 on day 1
    ("2026-03-02T00:00:00Z", 86400.0),           # a zone suffix is ignored: midnight, day 2
])
def test_time_date_from_a_data_field_fires_at_that_date(due: str | None, fires: float) -> None:
    """BPMN 2.0 Table 10.101 (TimerEventDefinition): "timeDate: Expression … The return type
    of the attribute timeDate MUST conform to the ISO-8601 format for date and time
    representations." — an expression, here ${due}, whose value is the date: the timer fires
    at the date the field holds when the timer is armed (the package's earliest calendar date,
    2026-03-01, is day 1 of the run)."""
    params = {} if due is None else {"due": due}
    outcome = run("time_date_from_data.bpmn", until=2 * 86400, params=params)
    assert (fires, "until_due") in completed(outcome)
    assert [e.time for e in kinds(outcome, "process.completed")] == [fires]


def test_a_value_that_is_no_date_stops_the_run_with_a_located_error() -> None:
    """A timeDate whose value is no date is never read as some default: the run stops with an
    error that names the timer's value and says what to write (as for any timer opspec
    cannot set: validate and run agree about timers)."""
    with pytest.raises(OpspecError) as caught:
        run("time_date_from_data.bpmn", until=86400, params={"due": "tomorrow"})
    assert "'tomorrow'" in caught.value.message and "no date" in caught.value.message
    assert "time_date_from_data.bpmn:8" in str(caught.value)
