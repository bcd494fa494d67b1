"""The report in sentences: its key findings (each estimate with its interval, in the spec's
own words where it has some; the hazards; how users differ and each subgroup's rates), and
how the report names a metric in prose and on an axis (:func:`words`, :func:`metric_label`:
"report latency", never ``report_latency_s``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from opspec.evaluation.no_spread_notes import marked
from opspec.evaluation.plan import span
from opspec.evaluation.tables import fmt, in_percent

__all__ = ["key_findings", "metric_label", "population_findings", "words"]


def words(name: str, unit: str | None = None) -> str:
    """A metric's name as words for an axis: ``report_latency_s`` with unit ``s`` is
    "report latency" (the unit goes in the axis label's brackets, not twice)."""
    text = name.replace("_", " ").strip()
    if unit and text.endswith(f" {unit}"):
        text = text[: -len(unit) - 1]
    return text


def metric_label(name: str, summary: Mapping[str, Any]) -> str:
    """A metric as the report's prose names it: the same words as its figure's axis
    (:func:`words`), so a reader meets "report latency", never ``report_latency_s``."""
    unit = summary.get("unit") or ("s" if summary.get("kind") == "duration" else None)
    return words(name, unit)


def _sentence_start(text: str) -> str:
    return text[:1].upper() + text[1:]


def _ci_words(summary: Mapping[str, Any], unit: str = "", *, percent: bool = False) -> str:
    low, high = summary.get("ci95") or [None, None]
    if low is None or high is None:
        return ""
    alike = ""
    if marked(summary):
        alike = (f"; all {summary['ci95_no_spread']['users']:,} users gave the same value, "
                 "so it shows no spread between users, not a value known exactly (unless the "
                 "spec fixes the value): more users would estimate one")
    return (f" (95 % confidence interval {fmt(low, unit, percent=percent)} to "
            f"{fmt(high, unit, percent=percent)}{alike})")


def _finding(metric: str, s: Mapping[str, Any], definition: Mapping[str, Any]
             ) -> str | None:
    """One estimate in a sentence, named by the spec's own words when it has some."""
    kind = s["kind"]
    # a ratio's description is a name ("Share of the doses due that were taken"); a count's
    # or a duration's is a definition, shown in "What each metric measures"
    words = (str(definition.get("description") or "").strip().rstrip(".")
             if kind == "ratio" else "")
    name = (words if words and len(words) <= 80
            else _sentence_start(metric_label(metric, s)))
    if kind == "count":
        if s.get("mean") is None:
            return None
        return (f"{name}: {fmt(s['mean'])} per user over the run{_ci_words(s)}, "
                f"{s['total']:,} in all.")
    if kind == "duration":
        unit = s.get("unit") or "s"
        if s.get("mean") is None:
            return f"{name}: no observations."
        return (f"{name}: {fmt(s['mean'], unit)} on average{_ci_words(s, unit)}; half took "
                f"at most {fmt(s['median'], unit)} and 95 % at most {fmt(s['p95'], unit)} "
                f"({s['n']:,} observations).")
    if s.get("value") is None:
        return None
    percent = in_percent(s)
    if words:
        of = ""
    elif percent and definition.get("denominator"):
        of = f" of {_words_of(definition.get('denominator'))}"
    else:
        of = (f" ({_words_of(definition.get('numerator'))} per "
              f"{_words_of(definition.get('denominator'))})")
    return f"{name}: {fmt(s['value'], percent=percent)}{of}{_ci_words(s, percent=percent)}."


def _words_of(metric: Any) -> str:
    return words(str(metric)) if metric else "?"


def key_findings(users: int, days: float, metrics: Mapping[str, Mapping[str, Any]],
                 definitions: Sequence[Mapping[str, Any]],
                 monitors: Mapping[str, Mapping[str, Any]], design_name: str) -> list[str]:
    """One design's key findings, a sentence each: who was simulated, every estimate (rates,
    then durations, then counts) and every hazard."""
    by_name = {d["name"]: d for d in definitions}
    lines = [f"{users:,} simulated users of {design_name}, each followed for {span(days)}."]
    order = ([n for n, s in metrics.items() if s["kind"] == "ratio"]
             + [n for n, s in metrics.items() if s["kind"] == "duration"]
             + [n for n, s in metrics.items() if s["kind"] == "count"])
    for name in order:
        sentence = _finding(name, metrics[name], by_name.get(name, {}))
        if sentence:
            lines.append(sentence)
    if not monitors:
        lines.append("Hazards: the spec declares no safety monitors (opspec:Monitor), so none "
                     "were watched.")
    for name, m in monitors.items():
        low, high = m.get("ci95") or [None, None]
        interval = (f" (95 % CI {fmt(low)} to {fmt(high)})" if low is not None
                    and high is not None else "")
        if m["violations"]:
            lines.append(f"Hazard {name}: {m['violations']:,} violations in "
                         f"{m['users_affected']} of {m['users']} users, "
                         f"{fmt(m['per_user_day'])} per user-day{interval}.")
        else:
            lines.append(f"Hazard {name}: never violated; at most {fmt(high)} per user-day "
                         "(upper 95 % bound)." if high is not None
                         else f"Hazard {name}: never violated.")
    return lines


def population_findings(metrics: Mapping[str, Mapping[str, Any]],
                        population: Mapping[str, Any] | None) -> list[str]:
    """How users differ in sentences: per rate, how many users had any event and the
    percentiles of their own rates; per subgroup, the rates."""
    lines = []
    for name, s in metrics.items():
        own = s.get("per_user") or {}
        if not in_percent(s) or not own.get("users") or own.get("share_with_any") is None:
            continue
        if own["share_with_any"] in (0.0, 1.0) and name.endswith("taken_rate"):
            continue
        low, high = own.get("share_with_any_ci95") or [None, None]
        lines.append(
            f"{_sentence_start(metric_label(name, s))} per user: "
            f"{own['users_with_any']:,} of {own['users']:,} users "
            f"({fmt(own['share_with_any'], percent=True)}, exact 95 % CI "
            f"{fmt(low, percent=True)} to {fmt(high, percent=True)}) had a rate above zero; "
            f"half the users had at most {fmt(own['median'], percent=True)}, 90 % at most "
            f"{fmt(own['p90'], percent=True)}, 99 % at most {fmt(own['p99'], percent=True)}.")
    groups = (population or {}).get("subgroups") or {}
    for group, entry in groups.items():
        rates = [f"{metric_label(n, m)} {fmt(m['value'], percent=True)}{_ci_words(m, percent=True)}"
                 for n, m in (entry.get("metrics") or {}).items()
                 if in_percent(m) and m.get("value") is not None]
        if rates:
            lines.append(f"Subgroup {group} ({entry['users']:,} users, "
                         f"{fmt(entry['share'], percent=True)}): " + "; ".join(rates) + ".")
    return lines

