"""The study's summary per variant: the intervals `opspec evaluate` gives a design (a count
nobody had, a rate of 0 in all doses are not [0, 0]), durations with their unit, each line
with its number of participants. Sessions are recorded by `opspec run --trace` (the model
user performs the lane), not through the terminal: only the summary is under test."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from scipy import stats

from opspec.cli import main
from opspec.tui.study import load_protocol, summary, summary_lines


def _done_by_model(protocol_file: Path) -> None:
    protocol = load_protocol(protocol_file)
    for i, participant in enumerate(protocol.participants):
        for session in protocol.sessions(participant):
            session.trace.parent.mkdir(parents=True, exist_ok=True)
            assert main(["run", str(session.variant.spec), "--days", "1", "--seed", str(i),
                         "--trace", str(session.trace)]) == 0
            session.done_marker.write_text(json.dumps({"spec": str(session.variant.spec)}),
                                           encoding="utf-8")


@pytest.mark.slow          # six simulated days
def test_rare_counts_and_rates_have_the_intervals_evaluate_gives(protocol_file: Path,
                                                                capsys) -> None:
    _done_by_model(protocol_file)
    capsys.readouterr()
    doc = summary(load_protocol(protocol_file))
    a = doc["variants"]["A"]["metrics"]
    # nobody's caregiver was notified: 0 events in 3 participants is not "certainly none";
    # the exact Poisson (Garwood) upper bound of the mean per participant is chi2(0.975, 2)/6
    notified = a["caregiver_notified"]
    assert notified["value"] == 0
    assert notified["ci95"][0] == 0
    assert notified["ci95"][1] == pytest.approx(stats.chi2.ppf(0.975, 2) / 2 / 3)
    # no dose missed of 12: Wilson's interval of 0/12, not [0, 0]
    missed = a["missed_rate"]
    assert missed["value"] == 0
    z2 = stats.norm.ppf(0.975) ** 2
    assert missed["ci95"][1] == pytest.approx(z2 / (12 + z2))
    assert missed["ci95_method"] == "wilson-neff"
    # a ratio the spec does not declare a proportion is a ratio, whatever its numbers
    assert a["alarms_per_dose"]["ci95_method"] in ("t", "t+garwood-rate")
    # a duration carries its unit, and every line its number of participants
    assert a["report_latency_s"]["unit"] == "s"
    out = "\n".join(summary_lines(doc))
    assert f"caregiver_notified: 0 (95 % CI [0, {notified['ci95'][1]:.4g}]; n = 3)" in out
    latency = next(line for line in out.splitlines() if "report_latency_s" in line)
    assert " s (95 % CI [" in latency and "] s; n = 3)" in latency
    # the JSON of the command says the same
    assert main(["study", str(protocol_file), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["variants"]["A"]["metrics"]["missed_rate"]["ci95"] == missed["ci95"]


def test_a_metric_without_an_interval_says_why() -> None:
    doc = {"study": "s", "status": {"P01": {"A": True, "B": True}},
           "variants": {"A": {"participants": 1, "metrics": {"report_latency_s": {
               "value": 12.5, "ci95": [None, None], "unit": "s", "participants": 1}}}},
           "comparisons": [{"a": "A", "b": "B", "participants": ["P01", "P02"],
                            "metrics": {"report_latency_s": {
                                "a": 12.5, "b": 10.0, "difference": -2.5,
                                "ci95": [None, None], "unit": "s", "participants": 2}}}]}
    lines = summary_lines(doc)
    assert "  report_latency_s: 12.5 s (no 95 % CI: one participant; n = 1)" in lines
    assert ("  report_latency_s: 12.5 s -> 10 s, difference -2.5 s (no 95 % CI: fewer than "
            "two participants differ between the variants; n = 2)") in lines
    assert not any("[-, -]" in line for line in lines)


def test_a_variants_ratio_gets_the_interval_its_declaration_calls_for() -> None:
    from opspec.model import MetricDefinition, MetricKind
    from opspec.statistics.ratios import FalseProportion
    from opspec.tui.study import variant_estimate

    def ratio(proportion: bool) -> MetricDefinition:
        return MetricDefinition(name="alarms_per_dose", kind=MetricKind.RATIO,
                                numerator="alarms", denominator="doses_due",
                                proportion=proportion)

    # every participant's alarms at most their doses: still a ratio, not capped at 1
    pairs = [(3.0, 4.0), (4.0, 4.0), (4.0, 4.0), (2.0, 4.0), (4.0, 4.0)]
    undeclared = variant_estimate("ratio", pairs, ratio(False), of_counts=True)
    assert undeclared["ci95_method"] == "t" and undeclared["ci95"][1] > 1.0
    declared = variant_estimate("ratio", pairs, ratio(True), of_counts=True)
    assert declared["ci95_method"] == "wilson-neff" and declared["ci95"][1] < 1.0
    with pytest.raises(FalseProportion, match="alarms_per_dose is declared a proportion"):
        variant_estimate("ratio", [*pairs, (5.0, 4.0)], ratio(True), of_counts=True)
