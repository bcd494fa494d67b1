"""`opspec run`'s metrics block shows a ratio of two counts as `opspec evaluate` does: a
ratio the spec declares a proportion (`Proportion="true"`) in percent, every ratio of counts
with the counts it divides, `(k of n)`; `--json` keeps the bare value, shaped as `opspec evaluate --json`."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.evaluation.run_metrics_text import metric_lines
from opspec.model import MetricDefinition, MetricKind

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
# 12 doses due over 3 days, all taken, 13 alarms (the run the README and docs show)
THREE_DAYS = ["--user-model", str(USERS), "--days", "3", "--seed", "1"]


def metrics_block(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, str]:
    """The text summary's metrics, name -> what follows the name."""
    status = main(["run", str(SPEC), "--timeline", "none", *args])
    assert status == 0
    lines = capsys.readouterr().out.splitlines()
    start = lines.index("metrics") + 1
    block = {}
    for line in lines[start:]:
        found = re.fullmatch(r"  (\S+) +(.+)", line)
        if found is None:
            break
        block[found[1]] = found[2]
    return block


def json_metrics(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, dict]:
    status = main(["run", str(SPEC), "--json", *args])
    assert status == 0
    return json.loads(capsys.readouterr().out)["metrics"]


def test_a_proportion_is_in_percent_as_evaluate_prints_it_with_its_counts(capsys):
    block = metrics_block(capsys, *THREE_DAYS)
    assert block["doses_due"] == "12" and block["doses_taken"] == "12"
    assert block["taken_rate"] == "100.00 % (12 of 12)"
    assert block["missed_rate"] == "0.00 % (0 of 12)"
    # the same formatter as evaluate's table (two decimals, a space before %)
    from opspec.evaluation.tables import fmt

    assert block["taken_rate"].startswith(fmt(1.0, percent=True))


def test_a_ratio_that_is_not_a_proportion_keeps_its_value_and_gains_its_counts(capsys):
    block = metrics_block(capsys, *THREE_DAYS)
    assert block["alarms"] == "13"
    assert block["alarms_per_dose"] == "1.083 (13 of 12)"


def test_alarms_per_dose_is_never_a_percentage_even_when_its_counts_are_equal(capsys):
    # one day of seed 1: 4 alarms for 4 doses; the spec does not declare this ratio a
    # proportion (a dose may have three alarms), so it is never in percent
    block = metrics_block(capsys, "--days", "1", "--seed", "1")
    assert block["alarms_per_dose"] == "1 (4 of 4)"
    assert block["taken_rate"] == "100.00 % (4 of 4)"


def test_a_zero_denominator_shows_no_value_and_the_empty_counts(capsys):
    # the first minute: no dose is due yet
    block = metrics_block(capsys, "--until", "60")
    assert block["doses_due"] == "0"
    assert block["taken_rate"] == "- (0 of 0)"
    assert block["missed_rate"] == "- (0 of 0)"
    assert block["alarms_per_dose"] == "- (0 of 0)"


@pytest.mark.parametrize("args", [THREE_DAYS, ["--until", "60"]])
def test_json_ratios_keep_the_bare_value_shaped_as_evaluate_json(capsys, args):
    metrics = json_metrics(capsys, *args)
    for name, numerator in (("alarms_per_dose", "alarms"), ("taken_rate", "doses_taken"),
                            ("missed_rate", "doses_missed")):
        due = metrics["doses_due"]["total"]
        value = metrics[numerator]["total"] / due if due else None
        assert metrics[name] == {"kind": "ratio", "value": value}
    if args == THREE_DAYS:
        assert metrics["taken_rate"] == {"kind": "ratio", "value": 1.0}
        assert metrics["alarms_per_dose"]["value"] == pytest.approx(13 / 12)


def test_ratios_of_durations_and_of_ratios_are_their_bare_value():
    def ratio(name: str, numerator: str, denominator: str) -> MetricDefinition:
        return MetricDefinition(name=name, kind=MetricKind.RATIO, numerator=numerator,
                                denominator=denominator)

    definitions = [ratio("wait_share", "wait_s", "trip_s"),
                   ratio("rate_of_rates", "wait_share", "wait_share"),
                   ratio("trip_rate", "trip_s", "missing")]
    metrics = {
        "wait_s": {"kind": "duration", "n": 0, "mean": None, "p95": None},
        "trip_s": {"kind": "duration", "n": 2, "mean": 4.0, "p95": 5.9},
        "wait_share": {"kind": "ratio", "value": 0.25},
        "rate_of_rates": {"kind": "ratio", "value": 1.0},
        "trip_rate": {"kind": "ratio", "value": None},
    }
    assert metric_lines(metrics, {"trip_s": 4.0}, definitions)[-3:] == [
        "  wait_share     0.25",
        "  rate_of_rates  1",
        "  trip_rate      -"]


def _counts_ratio(proportion: bool) -> list[MetricDefinition]:
    return [MetricDefinition(name="due", kind=MetricKind.COUNT),
            MetricDefinition(name="hit", kind=MetricKind.COUNT),
            MetricDefinition(name="hit_rate", kind=MetricKind.RATIO, numerator="hit",
                             denominator="due", proportion=proportion)]


def _counted(hit: int, due: int) -> dict[str, dict]:
    return {"due": {"kind": "count", "total": due}, "hit": {"kind": "count", "total": hit},
            "hit_rate": {"kind": "ratio", "value": hit / due}}


def test_percent_follows_the_declaration_not_the_name():
    # named like a rate and between 0 and 1, but not declared a proportion: its value
    assert metric_lines(_counted(3, 4), {}, _counts_ratio(False))[-1] == \
        "  hit_rate  0.75 (3 of 4)"
    assert metric_lines(_counted(3, 4), {}, _counts_ratio(True))[-1] == \
        "  hit_rate  75.00 % (3 of 4)"


def test_a_run_that_contradicts_a_declared_proportion_says_so_on_its_line():
    line = metric_lines(_counted(5, 4), {}, _counts_ratio(True))[-1]
    assert line == ("  hit_rate  1.25 (5 of 4: more hit than due, though the spec declares "
                    "it a proportion)")
