"""A study's summary writes a metric as `opspec run` and `opspec evaluate` do: a ratio the spec
declares a proportion in percent (it was a plain 0.0833 beside evaluate's 8.33 %), any other
ratio a plain number whatever its name, and a difference of two variants signed (+2.5 s; it
was 2.5 s, which read as a level), a proportion's in percentage points."""

from __future__ import annotations

from opspec.model import MetricDefinition, MetricKind
from opspec.tui.study import summary_lines, variant_estimate


def _ratio(name: str, proportion: bool) -> MetricDefinition:
    return MetricDefinition(name=name, kind=MetricKind.RATIO, numerator="doses_missed",
                            denominator="doses_due", proportion=proportion)


def test_a_declared_proportion_is_in_percent_and_differences_are_signed() -> None:
    pairs = [(1.0, 4.0), (0.0, 4.0), (0.0, 4.0)]
    cut = variant_estimate("ratio", pairs, _ratio("cut_sessions", True), of_counts=True)
    missed = variant_estimate("ratio", pairs, _ratio("missed_rate", False), of_counts=True)
    assert cut["proportion"] is True and missed["proportion"] is False
    doc = {"study": "s", "status": {},
           "variants": {"A": {"participants": 3, "metrics": {"cut_sessions": cut,
                                                           "missed_rate": missed}}},
           "comparisons": [{"a": "A", "b": "B", "participants": ["P01", "P02"], "metrics": {
               "cut_sessions": {"a": 0.25, "b": 0.125, "difference": -0.125,
                                "ci95": [-0.3, 0.05], "unit": None, "participants": 2,
                                "proportion": True},
               "report_latency_s": {"a": 10.0, "b": 12.5, "difference": 2.5,
                                    "ci95": [0.5, 4.5], "unit": "s", "participants": 2}}}]}
    lines = summary_lines(doc)
    variant = lines[lines.index("variant A (3 participant(s) finished):") + 1:][:2]
    shown = {line.split(":")[0].strip(): line for line in variant}
    assert shown["cut_sessions"].startswith("  cut_sessions: 8.33 % (95 % CI [")
    assert shown["cut_sessions"].endswith(" %]; n = 3)")
    assert shown["missed_rate"].startswith("  missed_rate: 0.08333 (95 % CI [")
    assert "%" not in shown["missed_rate"].replace("95 % CI", "")
    assert ("  cut_sessions: 25.00 % -> 12.50 %, difference -12.50 pp (95 % CI [-30.00 pp, "
            "+5.00 pp]; n = 2)") in lines
    assert ("  report_latency_s: 10 s -> 12.5 s, difference +2.5 s (95 % CI [+0.5, +4.5] s; "
            "n = 2)") in lines
