"""When a spec test fails, the plugin says what, with the values and a short trace slice."""

from __future__ import annotations

import re

import pytest

HEADER = 'SPEC = "specs/dispenser.xpdl"\nfrom opspec.testing import expect\n'


def _run(project: pytest.Pytester, body: str, *args: str) -> pytest.RunResult:
    project.makepyfile(HEADER + body)
    return project.runpytest(*args)


@pytest.mark.parametrize(("line", "listing"), [
    ("doses_tkn == 1", "the spec's metric names are: doses_due, doses_taken, doses_missed"),
    ("never activity dispence", "the spec's activity names are: *dispense*"),
    ("rate doses_taken/doses_dew >= 0.9 with 95% confidence",
     "the spec's metric names are: doses_due*"),
    ("never trigger trg_9", "the spec's trigger names are: trg_2, trg_1"),
], ids=["metric", "activity", "rate-denominator", "trigger"])
def test_an_expectation_naming_what_the_spec_lacks_lists_what_it_has(
        project: pytest.Pytester, line: str, listing: str) -> None:
    result = _run(project, f"""
def test_it(spec, simulate):
    expect(simulate(spec, until=3600), {line!r})
""")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*ConfigurationError: expect(): *which the spec does not have*"
                                 + listing + "*"])
    assert "opspec/testing/" not in result.stdout.str()   # no trip through our internals


def test_a_metric_the_spec_lacks_in_python_lists_the_metrics(project: pytest.Pytester) -> None:
    result = _run(project, """
def test_it(spec, simulate):
    simulate(spec, until=3600).value("doses")
""")
    result.stdout.fnmatch_lines([
        "*.py:5: *.value(\"doses\")",
        "ConfigurationError: the spec has no metric 'doses' (its metrics are: doses_due, *)"])


def test_a_script_naming_an_unknown_activity_lists_the_activities(
        project: pytest.Pytester) -> None:
    result = _run(project, """
def test_it(spec, simulate):
    simulate(spec, script=[("after trg_2 90s", "press_reprot")])
""")
    result.stdout.fnmatch_lines([("*simulate(): <script>: steps[[]0[]]: the script names activity "
                                  "'press_reprot', which the spec does not have (did you mean "
                                  "'press_report'*?) (known activities: *press_report*")])


def test_a_statistical_claim_with_too_few_replications_says_how_many_it_needs(
        project: pytest.Pytester) -> None:
    result = _run(project, """
def test_it(spec, simulate):
    result = simulate(spec, users=10, user_model="specs/dispenser.users.toml")
    expect(result, "rate doses_taken/doses_due >= 0.99 with 95% confidence")
""")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "*expected rate doses_taken/doses_due >= 0.99 with 95% confidence",
        ("*estimate * (*/40 doses_due, 10 replication(s)); 95% one-sided Wilson interval "
         "*; bound >= 0.99"),
        "*too few replications to decide: about * replications (~* doses_due) would*"])
    needed = int(re.search(r"about (\d+) replications", result.stdout.str())[1])  # type: ignore[index]
    assert needed > 10


def test_a_refuted_statistical_claim_says_it_is_false(project: pytest.Pytester) -> None:
    result = _run(project, """
def test_it(spec, simulate):
    result = simulate(spec, users=30, script=[("never", "press_report")])
    expect(result, "rate doses_taken/doses_due >= 0.5 with 95% confidence")
""")
    result.stdout.fnmatch_lines(["*estimate 0 (0/120 doses_due*", "*the claim is false*"])


def test_a_failing_trace_predicate_prints_a_slice_not_the_whole_trace(
        project: pytest.Pytester) -> None:
    result = _run(project, """
def test_it(spec, simulate):
    result = simulate(spec, days=3, script=[("never", "press_report")])
    print("EVENTS", len(result.trace))
    expect(result, "never activity notify_caregiver")
""", "-rN")
    result.assert_outcomes(failed=1)
    out = result.stdout.str()
    result.stdout.fnmatch_lines([
        "*expected never activity notify_caregiver",
        "*but activity notify_caregiver happened at d1 08:15:00 (the first of 12 violations)",
        "*trace around it (1 marked event(s) of *):",
        "*d1 08:1*notify_workflow*"])
    events = int(re.search(r"EVENTS (\d+)", out)[1])  # type: ignore[index]
    slice_lines = [line for line in out.splitlines() if re.match(r">?E?\s+d\d+ \d\d:", line)]
    assert events > 500 and 0 < len(slice_lines) <= 12


def test_a_metric_expectation_shows_the_value_and_the_events_it_counts(
        project: pytest.Pytester) -> None:
    result = _run(project, """
def test_it(spec, simulate):
    expect(simulate(spec, until=9 * 3600, script=[("never", "press_report")]),
           "alarms == 1")
""")
    result.stdout.fnmatch_lines([
        "*expected alarms == 1", "*but alarms = 3", "*alarms: total=3",
        "*d1 08:00:00*sound_alarm", "*d1 08:05:00*sound_alarm",
        "*d1 08:10:00*sound_alarm", "*(seed *, 1 replication(s))"])


def test_a_failing_test_shows_its_spec_argument_in_one_short_line(
        project: pytest.Pytester) -> None:
    # pytest shows a failing test's arguments: the spec's was 240 characters of its fields
    result = _run(project, """
def test_it(spec, simulate):
    result = simulate(spec, script=[("never", "press_report")], until=9 * 3600)
    assert result.value("doses_taken") == 1
""")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "spec = <Package 'medication_dispenser' from */specs/dispenser.xpdl: 4 process(es)>"])
    assert "extended_attribut" not in result.stdout.str()


def test_judging_the_spec_or_the_uncalled_fixture_says_to_call_simulate(
        project: pytest.Pytester) -> None:
    # were an AttributeError ('Package' object has no attribute 'names') or a TypeError
    # raised inside opspec, shown with opspec's source
    result = _run(project, """
from opspec.testing import assert_rate, check

def test_expect_on_the_spec(spec):
    expect(spec, "doses_taken == 1")

def test_a_rate_of_the_fixture(simulate):
    assert_rate(simulate, "taken_rate", at_least=0.9)

def test_a_predicate_on_the_fixture(simulate):
    check(simulate, "never dispense")

def test_a_predicate_on_a_number():
    check(42, "never dispense")
""", "-rN")
    result.assert_outcomes(failed=4)
    result.stdout.fnmatch_lines([
        ("E * TypeError: expect() judges a run, not the spec (Package): write "
         "expect(simulate(spec, ...), ...)"),
        ("E * TypeError: assert_rate() judges what simulate() returns, not the simulate fixture "
         "itself: call it, assert_rate(simulate(spec, ...), ...)"),
        "E * TypeError: check() judges what simulate() returns, not the simulate fixture itself*",
        "E * TypeError: check() judges a SimulationResult, a RunResult, *, not int"])
    out = result.stdout.str()
    assert "opspec/testing/" not in out and "AttributeError" not in out
