"""Monitors: safety properties watched during every run, from tests or from the spec."""

from __future__ import annotations

from pathlib import Path

import pytest
import scipy.stats

from opspec.engine.compiled import CompiledPackage
from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError
from opspec.properties.language import BoundedResponse, MinGap
from opspec.properties.monitors import package_monitors, parse_monitor
from opspec.statistics import poisson_interval
from opspec.testing import (
    assert_no_violations,
    max_count_per,
    min_gap,
    never,
    never_while,
    within,
)
from opspec.testing.simulation import simulate

from .conftest import DISPENSER, NINE

# a late report at 18:00 (290 s) and a prompt one at 22:00: dispenses 3 h 55 min apart
LATE_THEN_PROMPT = [("after trg_2 0s", "press_report"), ("after trg_2 0s", "press_report"),
                    ("after trg_2 290s", "press_report"), ("after trg_2 10s", "press_report")]


def _feed(monitor_text: str, events: list[tuple[float, str]], end: float) -> list[str]:
    run = parse_monitor(monitor_text).start()
    for seq, (time, activity) in enumerate(events, 1):
        run(TraceEvent(time, "activity.completed", "p", 1, activity, seq=seq))
    run.finish(end)
    return [v.message for v in run.violations]


@pytest.mark.parametrize("text, events, end, expected", [
    ("min_gap a 10s", [(0, "a"), (10, "a"), (15, "a")], 20, ["5 s apart"]),
    ("min_gap a 10s", [(0, "a"), (10, "a"), (20, "a")], 20, []),
    ("never b", [(0, "a"), (3, "b")], 5, ["b happened at d1 00:00:03"]),
    ("max_count a 2 per 1 min", [(0, "a"), (30, "a"), (59, "a"), (90, "a")], 100,
     ["3 times within 59 s"]),
    ("max_count a 2 per 1 min", [(0, "a"), (30, "a"), (60, "a"), (90, "a")], 100, []),
    ("bounded_response a b 10s", [(0, "a"), (5, "b"), (20, "a"), (40, "x")], 50,
     ["a at d1 00:00:20 was not followed by b within 10 s"]),
    ("bounded_response a b|c 10s", [(0, "a"), (10, "c")], 50, []),
    ("bounded_response a b 10s", [(0, "a"), (11, "b")], 50, ["was not followed by b within 10 s; the next came at d1 00:00:11"]),
    ("bounded_response a b 10s", [(45, "a")], 50, []),      # window cut off by the end
    ("never_while d after m until s", [(0, "m"), (5, "d"), (6, "s"), (7, "d")], 10,
     ["d at d1 00:00:05, after m at d1 00:00:00 and before any s"]),
], ids=["min-gap-broken", "min-gap-exact", "never", "max-count-broken", "max-count-sliding",
        "response-late", "response-alternative", "response-one-second-late",
        "response-cut-off", "never-while"])
def test_monitor_text_forms_catch_exactly_their_violations(
        text: str, events: list[tuple[float, str]], end: float, expected: list[str]) -> None:
    found = _feed(text, events, end)
    assert len(found) == len(expected)
    for message, part in zip(found, expected, strict=True):
        assert part in message


@pytest.mark.parametrize("text, match", [
    ("min_gap dispense", "cannot read the monitor"),
    ("min_gap dispense soon", "cannot read duration 'soon': not a duration"),
    ("always dispense", "monitor forms: 'min_gap A 4h'"),
    ("never trigger:", "cannot read 'trigger:'"),
], ids=["no-duration", "bad-duration", "unknown-form", "bad-subject"])
def test_an_unreadable_monitor_says_what_is_wrong(text: str, match: str) -> None:
    with pytest.raises(ConfigurationError, match=match):
        parse_monitor(text)


def test_the_4_hour_gap_is_broken_by_a_late_then_prompt_report_and_3h45m_is_not(
        dispenser: CompiledPackage) -> None:
    result = simulate(dispenser, script=LATE_THEN_PROMPT, days=1,
                      monitors=[min_gap("dispense", hours=4), "min_gap dispense 225 min"])
    report = result.monitor_report()
    four, safe = report.row("min_gap dispense 4h"), report.row("min_gap dispense 225 min")
    assert (four.violations, safe.violations) == (1, 0)
    (violation,) = four.first
    assert violation.time == 22 * 3600 + 10
    assert [e.activity for e in violation.events] == ["dispense", "dispense"]
    assert "18:04:50 and again at d1 22:00:10, 3 h 55 min 20 s apart" in violation.message
    assert not report.ok
    with pytest.raises(AssertionError, match=r"(?s)min_gap dispense 4h: 1 violation.*"
                                             r"#10 notify_workflow +activity.completed +dispense"):
        assert_no_violations(result)
    assert_no_violations(result, "min_gap dispense 225 min")


def test_a_monitor_is_named_by_any_spelling_of_its_property(
        dispenser: CompiledPackage) -> None:
    # by its text only, "min_gap dispense 3h45m" was "no monitor" in a result watching
    # min_gap("dispense", minutes=225) (whose text is "min_gap dispense 3.75h")
    result = simulate(dispenser, script=LATE_THEN_PROMPT, days=1,
                      monitors=[min_gap("dispense", minutes=225), "min_gap dispense 4h"])
    for same in ("min_gap dispense 3h45m", "never dispense twice within 225 min",
                 "MIN_GAP dispense PT3H45M"):
        assert_no_violations(result, same)
    assert result.monitor_report().row("min_gap dispense 240min").violations == 1
    with pytest.raises(AssertionError, match="min_gap dispense 4h: 1 violation"):
        assert_no_violations(result, "never dispense twice within 4 h")
    with pytest.raises(ConfigurationError, match=r"no monitor 'min_gap dispense 3h' in this "
                                                 r"result \(its monitors are: min_gap "
                                                 r"dispense 3.75h, min_gap dispense 4h\)"):
        assert_no_violations(result, "min_gap dispense 3h")


def test_python_constructors_build_the_same_monitors_as_the_text_form() -> None:
    assert min_gap("dispense", hours=4) == parse_monitor("min_gap dispense 4h")
    assert within("a", "b", 60) == BoundedResponse(
        *parse_monitor("bounded_response a b 60s").subjects(), 60.0,
        text="bounded_response a b 60s")
    assert within("a", "b", 60).text == "bounded_response a b 1min"
    assert max_count_per("a", 4, hours=24).text == "max_count a 4 per 24h"
    assert never("a").text == "never a"
    assert never_while("a", after="b", until="c") == parse_monitor(
        "never_while a after b until c")
    assert isinstance(parse_monitor("min_gap   dispense    PT4H"), MinGap)


def test_a_monitor_naming_an_unknown_activity_lists_the_spec_names(
        dispenser: CompiledPackage) -> None:
    with pytest.raises(ConfigurationError, match="monitor 'min_gap dispence 4h': the spec has "
                                                 "no activity, trigger or process 'dispence'"
                                                 r".*dispense"):
        simulate(dispenser, until=NINE, monitors=["min_gap dispence 4h"])


def test_monitors_declared_in_the_spec_run_in_every_simulation(tmp_path: Path) -> None:
    text = DISPENSER.read_text(encoding="utf-8").replace(
        '<ExtendedAttribute Name="opspec:Metrics">',
        '<ExtendedAttribute Name="opspec:Monitor" Value="min_gap dispense 4h"/>\n'
        '    <ExtendedAttribute Name="opspec:Monitor">max_count dispense 4 per 24h  # a day\n'
        '      never notify_caregiver</ExtendedAttribute>\n'
        '    <ExtendedAttribute Name="opspec:Metrics">', 1)
    spec = tmp_path / "dispenser.xpdl"
    spec.write_text(text, encoding="utf-8")
    result = simulate(spec, script=LATE_THEN_PROMPT, days=1)
    report = result.monitor_report()
    assert [r.monitor for r in report.rows] == ["min_gap dispense 4h",
                                                "max_count dispense 4 per 24h",
                                                "never notify_caregiver"]
    assert [r.violations for r in report.rows] == [1, 0, 0]


def test_a_bad_monitor_in_the_spec_is_reported_at_its_line(tmp_path: Path) -> None:
    from opspec.xpdl.loader import load_spec

    text = DISPENSER.read_text(encoding="utf-8").replace(
        '<ExtendedAttribute Name="opspec:Metrics">',
        '<ExtendedAttribute Name="opspec:Monitor" Value="min_gap dispense whenever"/>\n'
        '    <ExtendedAttribute Name="opspec:Metrics">', 1)
    spec = tmp_path / "dispenser.xpdl"
    spec.write_text(text, encoding="utf-8")
    package = load_spec(spec)
    line = 1 + text[:text.index("whenever")].count("\n")
    with pytest.raises(ConfigurationError, match=rf"dispenser.xpdl:{line}: monitor "
                                                 "'min_gap dispense whenever'"):
        package_monitors(package.extended_attributes)


def test_violations_over_many_users_become_a_hazard_per_user_day(
        dispenser: CompiledPackage) -> None:
    result = simulate(dispenser, users=20, days=2, user_model="dispenser-reference",
                      seed=3, monitors=[min_gap("dispense", hours=4)])
    row = result.monitor_report().row("min_gap dispense 4h")
    assert row.user_days == 40 and row.replications == 20
    assert row.violations > 0 and row.hazard == row.violations / 40
    assert row.hazard_lo < row.hazard < row.hazard_hi
    assert "per user-day" in str(result.monitor_report())


@pytest.mark.parametrize("count, exposure", [(0, 10.0), (1, 1.0), (7, 40.0), (98, 100.0),
                                             (1500, 3.0)])
def test_the_hazard_interval_is_the_exact_garwood_interval(count: int, exposure: float) -> None:
    rate, lo, hi = poisson_interval(count, exposure, 0.95)
    chi2 = scipy.stats.chi2
    expected_lo = 0.0 if count == 0 else chi2.ppf(0.025, 2 * count) / 2 / exposure
    expected_hi = chi2.ppf(0.975, 2 * count + 2) / 2 / exposure
    assert rate == count / exposure
    assert lo == pytest.approx(expected_lo, rel=1e-6)
    assert hi == pytest.approx(expected_hi, rel=1e-6)


def test_monitors_see_the_same_violations_whether_or_not_traces_are_kept(
        dispenser: CompiledPackage) -> None:
    watch = [min_gap("dispense", hours=4), "bounded_response process:notify_workflow dispense 5min"]

    def run(keep: bool) -> list[tuple[str, float, str, int]]:
        result = simulate(dispenser, users=15, days=2, user_model="dispenser-reference",
                          seed=2, keep_trace=keep, monitors=watch)
        return [(v.monitor, v.time, v.message, v.replication)
                for row in result.monitor_report().rows for v in row.first]

    kept = run(True)
    assert kept == run(False)
    assert {m for m, *_ in kept} == {"min_gap dispense 4h",
                                     "bounded_response process:notify_workflow dispense 5min"}
