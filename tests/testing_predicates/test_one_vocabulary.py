"""One Python vocabulary for the property language (issue 27): every constructor gives one
object that is a monitor (watched while the run happens) and a trace predicate (judged on the
stored trace), with the same verdict and witness either way; ``opspec.testing`` and the two
older modules hand out the very same constructors; the two older spellings of the same
properties (``never_happens``, ``bounded_response``) are deprecated aliases."""

from __future__ import annotations

import math
import warnings

import pytest

import opspec.properties.vocabulary as vocabulary
import opspec.testing as testing
from opspec.errors import ConfigurationError
from opspec.properties.language import Property
from opspec.properties.text_form import parse_property
from opspec.testing.predicates import failures
from opspec.testing.simulation import simulate

from .conftest import DISPENSER, USERS

# one of each shape the vocabulary spells, with its text form
SPELLINGS = [
    (lambda: testing.never("notify_caregiver"), "never notify_caregiver"),
    (lambda: testing.eventually("record_missed"), "eventually record_missed"),
    (lambda: testing.within("sound_alarm", "dispense", 120),
     "bounded_response sound_alarm dispense 2min"),
    (lambda: testing.within("sound_alarm", "dispense|record_missed", math.inf),
     "response sound_alarm dispense|record_missed"),
    (lambda: testing.happens_before("press_report", "dispense", each=True),
     "press_report before each dispense"),
    (lambda: testing.count("sound_alarm") <= 8, "count sound_alarm <= 8"),
    (lambda: testing.count("dispense").between(7, 8), "count dispense in [7, 8]"),
    (lambda: testing.min_gap("dispense", hours=4), "min_gap dispense 4h"),
    (lambda: testing.max_count_per("sound_alarm", 3, hours=6), "max_count sound_alarm 3 per 6h"),
    (lambda: testing.never_while("dispense", after="record_missed", until="sound_alarm"),
     "never_while dispense after record_missed until sound_alarm"),
    (lambda: testing.monitor("never press_report"), "never press_report"),
]


def test_opspec_testing_hands_out_the_vocabulary_itself() -> None:
    for name in vocabulary.__all__:
        if hasattr(testing, name):
            assert getattr(testing, name) is getattr(vocabulary, name), name
    from opspec.testing import monitors, predicates

    for module in (monitors, predicates):
        for name in ("min_gap", "max_count_per", "never_while", "monitor"):
            assert getattr(module, name) is getattr(vocabulary, name)
    for name in ("within", "never", "count", "happens_before", "eventually"):
        assert getattr(predicates, name) is getattr(vocabulary, name)


@pytest.mark.parametrize(("make", "text"), SPELLINGS, ids=[t for _, t in SPELLINGS])
def test_each_spelling_is_the_property_of_its_text(make, text: str) -> None:
    made = make()
    assert made == parse_property(text)
    assert isinstance(made.monitor(), Property)


def test_one_object_is_a_monitor_and_a_predicate_with_the_same_verdict() -> None:
    """Watched online in every replication (simulate(monitors=...)) and judged offline on the
    stored traces, each object gives the same violations at the same events."""
    made = [make() for make, _ in SPELLINGS]
    result = simulate(DISPENSER, users=3, days=2, seed=5, user_model=USERS, monitors=made)
    by_text: dict[str, list] = {}
    for r in result.monitor_results:
        by_text.setdefault(r.monitor, []).append(r)
    broken = 0
    for item in made:
        online = by_text[item.text]
        assert len(online) == 3                       # one per replication
        for replication, trace in enumerate(result.traces):
            offline = item.monitor().judge(trace, end=result.horizon)
            assert [(v.time, [e.seq for e in v.events]) for v in offline.violations] == [
                (v.time, [e.seq for e in v.events]) for v in online[replication].violations]
        judged = failures(result, item, first=False)
        assert len(judged) == sum(1 for r in online if r.count)
        broken += bool(judged)
    # the set holds properties that hold and properties that are broken
    assert 0 < broken < len(made)


def test_a_combination_is_a_predicate_but_not_a_monitor() -> None:
    both = testing.never("notify_caregiver") & testing.min_gap("dispense", hours=4)
    with pytest.raises(ConfigurationError, match="cannot be watched as a monitor") as error:
        simulate(DISPENSER, days=1, seed=1, user_model=USERS, monitors=[both])
    assert "monitors=[p, q]" in error.value.hint


def test_the_older_spellings_are_deprecated_aliases_of_the_same_property() -> None:
    with pytest.warns(DeprecationWarning, match=r"use never\(\)"):
        old = testing.never_happens("a")
    assert old == testing.never("a")
    with pytest.warns(DeprecationWarning, match=r"use within\(\)"):
        old = testing.bounded_response("a", "b", 60)
    assert old == testing.within("a", "b", 60)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        testing.within("a", "b", 60)
        testing.never("a")
