"""The predicates, assertions and monitors inside pytest runs: what a failing test shows."""

from __future__ import annotations

import pytest

from .conftest import DISPENSER

HEADER = f'''
from opspec.testing import (assert_no_violations, assert_rate, check, count, min_gap, never,
                            within)

SPEC = {str(DISPENSER)!r}
PROMPT = [("after trg_2 90s", "press_report")]
'''


def _run(pytester: pytest.Pytester, body: str) -> pytest.RunResult:
    pytester.makepyfile(test_spec=HEADER + body)
    return pytester.runpytest()


def test_a_failing_predicate_shows_the_claim_the_slice_and_the_seed(
        pytester: pytest.Pytester) -> None:
    result = _run(pytester, '''
def test_prompt(spec, simulate):
    check(simulate(spec, script=PROMPT, until=9 * 3600), within("sound_alarm", "press_report", 60))
''')
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "*check(simulate(spec, script=PROMPT*",
        "E * expected within(sound_alarm, press_report, 60 s)",
        "E * but activity sound_alarm at d1 08:00:00 was not followed by activity press_report within 1 min*",
        "E * trace around it (2 marked event(s) of *):",
        "E *>   d1 08:00:00        #2 notify_workflow    activity.completed   sound_alarm",
        "*- opspec -*", "seed * (from --opspec-seed=0 and the test id*"])
    assert "predicates.py" not in result.stdout.str()       # the test line, not opspec's


def test_an_unknown_name_fails_with_the_names_the_spec_has_and_no_traceback(
        pytester: pytest.Pytester) -> None:
    result = _run(pytester, '''
def test_typo(spec, simulate):
    check(simulate(spec, script=PROMPT, until=9 * 3600), never("notify_caregivr"))
''')
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        ("test_spec.py:*: check(simulate(spec, script=PROMPT, until=9 * 3600), "
        "never(\"notify_caregivr\"))"),
        ("ConfigurationError: the spec has no activity, trigger or process 'notify_caregivr' "
        "(its activities are: *notify_caregiver*")])
    assert "Traceback" not in result.stdout.str()


def test_a_trace_file_that_is_not_there_is_named_with_the_place_looked_at(
        pytester: pytest.Pytester) -> None:
    # was a FileNotFoundError through the predicates' and the trace reader's frames
    result = _run(pytester, '''
from opspec.testing import holds

def test_stored(spec):
    assert holds("runs/monday.jsonl", "never notify_caregiver", spec=spec)
''')
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "test_spec.py:*: assert holds(\"runs/monday.jsonl\", \"never notify_caregiver\", spec=spec)",
        (f"ConfigurationError: runs/monday.jsonl: no trace file there (looked at "
         f"{pytester.path}/runs/monday.jsonl); a relative path is from the folder pytest "
         "runs in; write a trace with opspec run SPEC --trace FILE*")])
    assert "FileNotFoundError" not in result.stdout.str()


def test_too_few_users_for_a_rate_say_how_many_are_needed(pytester: pytest.Pytester) -> None:
    result = _run(pytester, '''
def test_rate(spec, simulate):
    assert_rate(simulate(spec, script=PROMPT, users=3), "taken_rate", at_least=0.99)
''')
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "E * expected rate taken_rate >= 0.99 with 95% confidence",
        "E * estimate 1 (12/12 doses_due, 3 replication(s)); n = 12",
        "E * 95% one-sided Wilson interval ?0.*, 1?; bound >= 0.99",
        ("E * too few replications to decide: about * replications would, if the estimate "
        "stays at 1")])


def test_a_monitor_violation_fails_with_the_events_that_broke_it(
        pytester: pytest.Pytester) -> None:
    result = _run(pytester, '''
LATE_THEN_PROMPT = [("after trg_2 0s", "press_report"), ("after trg_2 0s", "press_report"),
                    ("after trg_2 290s", "press_report"), ("after trg_2 10s", "press_report")]

def test_gap(spec, simulate):
    assert_no_violations(simulate(spec, script=LATE_THEN_PROMPT, monitors=[min_gap("dispense", hours=4)]))
''')
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "E * monitor violations:",
        "E * min_gap dispense 4h: 1 violation(s) in 1/1 replication(s); 1 per user-day *",
        ("E * min_gap dispense 4h: d1 22:00:10: activity dispense at d1 18:04:50 and "
        "again at d1 22:00:10, 3 h 55 min 20 s apart (at least 4 h required)"),
        "E *d1 18:04:50 * activity.completed   dispense"])
