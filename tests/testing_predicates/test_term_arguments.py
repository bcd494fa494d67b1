"""A term of the property language given a value of the wrong kind is a ConfigurationError
naming the term as written, the value and what the term takes: ``count("x") == "3"`` raised a
TypeError through opspec/properties/property_terms.py (a traceback in a spec test), a
duration given as text to ``within`` was "seconds must be >= 0", ``min_gap(..., hours="2")``
a TypeError from ``float`` arithmetic, a number as an event's name a TypeError from ``re`` or
nothing at all (``activity_completed(3)``: never matched); in the text form, a count compared
with a duration only "cannot read the monitor"."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest

from opspec.errors import ConfigurationError
from opspec.properties.vocabulary import (
    activity_completed,
    count,
    event,
    happens_before,
    max_count_per,
    min_gap,
    monitor,
    never,
    never_while,
    per_instance,
    trigger_raised,
    within,
)


def _said(make: Callable[[], Any]) -> str:
    with pytest.raises(ConfigurationError) as refused:
        make()
    return str(refused.value)


@pytest.mark.parametrize(("make", "says"), [
    (lambda: count("x") == "3", ("count(x) == '3': a count compares with a number (of events), "
                                "not the text '3' (write 3, without quotes)")),
    (lambda: count("x") != "3", "count(x) != '3': a count compares with a number"),
    (lambda: count("x") < "3", "count(x) < '3': a count compares with a number"),
    (lambda: count("x") <= None, ("count(x) <= None: a count compares with a number (of events), "
                                 "not None")),
    (lambda: count("x") > True, ("count(x) > True: a count compares with a number (of events), "
                                "not the truth value True")),
    (lambda: count("x") >= math.nan,  # noqa: PLW0177  (nan is the value refused)
     "count(x) >= nan: a count compares with a number"),
    (lambda: count("x").at_least("2"), "count(x) >= '2': a count compares with a number"),
    (lambda: count("x").exactly("two"), ("count(x) == 'two': a count compares with a number "
                                        "(of events), not the text 'two'")),
    (lambda: count("x").between("1", 3), ("count(x).between('1', 3): a count compares with a "
                                         "number (of events), not the text '1'")),
], ids=["eq", "ne", "lt", "le-none", "gt-bool", "ge-nan", "at-least", "exactly", "between"])
def test_a_count_compared_with_what_is_no_number(make: Callable[[], Any], says: str) -> None:
    assert _said(make).startswith(says)


def test_a_count_compared_with_a_number_is_as_before() -> None:
    import numpy as np

    assert str(count("x") == 3) == "count(x) == 3"
    assert str(count("x").between(1, 4)) == "count(x) between 1 and 4"
    assert str(count("x") <= np.int64(2)) == "count(x) <= 2"        # numpy's numbers too


@pytest.mark.parametrize(("make", "says"), [
    (lambda: within("a", "b", "5 min"),
     ("within(a, b, '5 min'): seconds takes a number of seconds >= 0 (math.inf: by the end of "
     "the run), not the text '5 min'; write 300 (the seconds of '5 min')")),
    (lambda: within("a", "b", None), "within(a, b, None): seconds takes a number of seconds"),
    (lambda: min_gap("dispense", hours="2"),
     "min_gap(): hours= takes a number, not the text '2' (write 2, without quotes)"),
    (lambda: min_gap("dispense", seconds="abc"), ("min_gap(): seconds= takes a number, not the "
                                                 "text 'abc'")),
    (lambda: max_count_per("dispense", 4, minutes="90"),
     "max_count_per(): minutes= takes a number, not the text '90'"),
], ids=["within-text", "within-none", "min-gap-hours", "min-gap-seconds", "max-count-minutes"])
def test_a_time_given_as_text(make: Callable[[], Any], says: str) -> None:
    assert _said(make).startswith(says)


def test_a_time_as_a_number_is_as_before() -> None:
    assert str(within("a", "b", 300)) == "within(a, b, 300 s)"
    assert str(min_gap("dispense", hours=4)) == "min_gap dispense 4h"
    assert "within(): seconds must be >= 0, not -1" in _said(lambda: within("a", "b", -1))


@pytest.mark.parametrize(("make", "says"), [
    (lambda: count(3), "count(): expected an event name, a Match or a callable, not 3"),
    (lambda: never(None), "never(): expected an event name, a Match or a callable, not None"),
    (lambda: within(1, "b", 5), "within(): expected an event name"),
    (lambda: happens_before("a", 2.5), "happens_before(): expected an event name"),
    (lambda: min_gap(5, hours=1), "min_gap(): an event is named by text"),
    (lambda: never_while("a", after=3, until="b"), "never_while(): an event is named by text"),
    (lambda: max_count_per(7, 4, hours=24), "max_count_per(): an event is named by text"),
    (lambda: monitor(5), "monitor(): takes a property's text form"),
    (lambda: never("a") & 3, ("expected a predicate, a property, its text or an event name, "
                             "not 3")),
    (lambda: activity_completed(3), "activity_completed(): the activity is named by text, not 3"),
    (lambda: trigger_raised(1), "trigger_raised(): the trigger is named by text, not 1"),
    (lambda: event(3), "event(): the kind is text ('activity.omitted'), not 3"),
    (lambda: per_instance(3, never("a")), "per_instance(): the process is named by text, not 3"),
], ids=["count", "never", "within", "happens-before", "min-gap", "never-while", "max-count",
        "monitor", "and", "activity-completed", "trigger-raised", "event", "per-instance"])
def test_a_number_where_a_name_goes(make: Callable[[], Any], says: str) -> None:
    assert _said(make).startswith(says)


@pytest.mark.parametrize(("text", "says"), [
    ("count dispense <= 3s", "a count compares with a number (of events), not '3s'"),
    ("count dispense == many", "a count compares with a number (of events), not 'many'"),
    ("count dispense in [a, 3]", "a count compares with a number (of events), not 'a'"),
    ("max_count dispense 4h per 24h", "'4h' is not a whole number >= 0"),
], ids=["count-duration", "count-word", "count-range", "max-count-duration"])
def test_the_text_form_says_the_same(text: str, says: str) -> None:
    assert _said(lambda: monitor(text)).startswith(f"monitor {text!r}: {says}")


def test_a_spec_test_shows_it_as_its_line_and_one_message(pytester: pytest.Pytester) -> None:
    pytester.makepyfile(test_it="""
from opspec.testing import count

def test_it():
    count("dispense") == "3"
""")
    result = pytester.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["test_it.py:4: count(\"dispense\") == \"3\"",
                                 ("ConfigurationError: count(dispense) == '3': a count compares "
                                 "with a number (of events), not the text '3'*")])
    assert "opspec/properties/" not in result.stdout.str()
