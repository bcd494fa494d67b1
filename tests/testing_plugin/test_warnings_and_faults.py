"""What the pytest plugin shows that a test would otherwise lose: validate's warnings on a spec
the tests simulate (at the end of the session, and in a failing test's report), and a fault
that cut a replication short (a statistical assertion or a scenario over it fails naming the
fault's file:line; it never passes on truncated runs)."""

from __future__ import annotations

import pytest

from .conftest import DISPENSER

# an activity set no block uses: validate warns (line 79 of the copy), the spec still runs
UNUSED_SET = ('<ActivitySets><ActivitySet Id="never_used"><Activities><Activity Id="idle">'
              '<Route/></Activity></Activities></ActivitySet></ActivitySets>\n      ')
BROKEN = "alarms &lt; 3 and 1 / (alarms - 2) &gt; -99"     # the second re-alarm divides by 0


def _with_warning(project: pytest.Pytester) -> None:
    text = DISPENSER.read_text(encoding="utf-8")
    at = text.index("<Activities>", text.index('<WorkflowProcess Id="timer_workflow"'))
    (project.path / "specs" / "warned.xpdl").write_text(text[:at] + UNUSED_SET + text[at:],
                                                        encoding="utf-8")


def _broken(project: pytest.Pytester) -> None:
    text = DISPENSER.read_text(encoding="utf-8")
    (project.path / "specs" / "dispenser.xpdl").write_text(
        text.replace("<Expression>alarms &lt; 3</Expression>",
                     f"<Expression>{BROKEN}</Expression>"), encoding="utf-8")


def test_a_spec_warning_is_shown_at_the_end_of_a_green_session(
        project: pytest.Pytester) -> None:
    _with_warning(project)
    project.makepyfile('''
SPEC = "specs/warned.xpdl"

def test_runs(spec, simulate):
    assert simulate(spec, until=3600, no_user=True).runs

def test_runs_by_path(simulate):
    assert simulate("specs/warned.xpdl", until=3600, no_user=True).runs
''')
    result = project.runpytest()
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines([
        "*= opspec: warnings on the specs simulated =*",
        "*warned.xpdl:79: warning: activity set 'never_used' of process 'timer_workflow' is "
        "used by no BlockActivity*"])
    assert result.stdout.str().count("activity set 'never_used'") == 1     # once, not per test


def test_a_failing_test_shows_the_warnings_of_what_it_simulated(
        project: pytest.Pytester) -> None:
    _with_warning(project)
    project.makepyfile('''
def test_fails(simulate):
    simulate("specs/warned.xpdl", until=3600, no_user=True)
    assert False
''')
    result = project.runpytest()
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*- opspec -*", "seed * (from --opspec-seed=0*",
                                 "*warned.xpdl:79: warning: activity set 'never_used'*"])


def test_a_statistical_assertion_over_faulted_runs_fails_naming_the_fault(
        project: pytest.Pytester) -> None:
    _broken(project)
    project.makepyfile('''
from opspec.testing import assert_rate

def test_few_missed(simulate):
    result = simulate("specs/dispenser.xpdl", users=6, days=3, seed=2)
    assert_rate(result, "missed_rate", at_most=0.5)
''')
    result = project.runpytest()
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "E * of 6 replication(s) failed: a run-time fault or a deadlock of the spec cut them "
        "short, so no statistic over them is judged",
        "E *replication *: fault: *dispenser.xpdl:*: activity 'R'*division by zero*",
        "*failed replication *: fault: *dispenser.xpdl*"])


def test_a_scenario_file_over_faulted_runs_fails_naming_the_fault(
        project: pytest.Pytester) -> None:
    _broken(project)
    (project.path / "missed.scenario.toml").write_text(
        'spec = "specs/dispenser.xpdl"\n[[scenario]]\nname = "few doses missed"\n'
        'given = { users = 6, days = 3, seed = 2 }\n'
        'then = ["rate doses_missed/doses_due <= 0.5 with 95% confidence"]\n',
        encoding="utf-8")
    result = project.runpytest()
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "missed.scenario.toml:2: scenario[[]0[]]: * of 6 replication(s) failed*",
        "*replication *: fault: *dispenser.xpdl:*: activity 'R'*division by zero*"])


def test_a_spec_warning_is_shown_at_the_end_of_a_session_run_on_xdist_workers(
        project: pytest.Pytester) -> None:
    # with -n 2 the workers saw the warnings and the controller printed none
    _with_warning(project)
    project.makepyfile('''
SPEC = "specs/warned.xpdl"

def test_runs(spec, simulate):
    assert simulate(spec, until=3600, no_user=True).runs

def test_runs_too(spec, simulate):
    assert simulate(spec, until=3600, no_user=True).runs
''')
    result = project.runpytest_subprocess("-n", "2")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines([
        "*= opspec: warnings on the specs simulated =*",
        "*warned.xpdl:79: warning: activity set 'never_used'*"])
    assert result.stdout.str().count("activity set 'never_used'") == 1
