"""The evaluation report: ``report.html`` (self-contained, rendered from a Jinja2 template a
researcher can replace) and ``report.md`` with PNG figures, built from the result store alone
(so a resumed or re-reported run gives the same report).

What a reader gets, in order: key findings in plain words (estimates with their intervals,
hazards); what was run; what each metric measures (from which event to which event a
duration runs, what a count counts); who the simulated users are (every user-model
parameter, with its source); the estimates (table and figure, each rate on its own scale);
how users differ (each user's own rate or mean duration: a table and histograms); each
duration's distribution; counts day by day and by hour (each on its own scale); the user's
actions per activity; hazards from the spec's monitors (or that none were declared); with
two designs the paired differences; failed replications; how to read the intervals.

Figures and tables show the same numbers: every figure is drawn once per metric from the
same summaries as the tables; where a figure draws a sample of many observations its
caption says so, and the marks in it (mean, median, p95) are of all observations.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from opspec.evaluation.describe import (
    correlation_rows,
    describe_metric,
    population_notes,
    user_model_notes,
    user_model_rows,
    variation_rows,
)
from opspec.evaluation.plan import span
from opspec.evaluation.store import ResultStore
from opspec.evaluation.summary import (
    compare_designs,
    metric_definitions,
    subgroup_users,
    summarise_activities,
    summarise_design,
    summarise_monitors,
    summarise_population,
    per_user_values,
    user_pairs,
)
from opspec.evaluation.tables import (
    DISTRIBUTION_HEADERS,
    METRIC_HEADERS,
    MONITOR_HEADERS,
    PARAMETER_HEADERS,
    PER_USER_HEADERS,
    SUBGROUP_HEADERS,
    comparison_rows,
    distribution_rows,
    fmt,
    is_rate,
    method_name,
    metric_rows,
    monitor_rows,
    parameter_rows,
    per_user_rows,
    subgroup_comparison_rows,
    subgroup_metric_rows,
    subgroup_rows,
)
from opspec.files import file_name

__all__ = ["PLOT_SAMPLE", "Summaries", "write_report"]

# Figures draw at most this many observations per metric (a deterministic, even thinning,
# said in the caption); the statistics and the marks in the figure always use all of them.
PLOT_SAMPLE = 50_000

#: What the evaluate command has already computed, per design label: ``metrics``,
#: ``monitors``; and ``difference`` for a comparison. Passed in so nothing is computed twice.
Summaries = Mapping[str, Any]


def _observations(store: ResultStore, design: str, metric: str) -> tuple[list[float], int]:
    """The observations a figure draws (every one, or an even sample) and how many exist."""
    total = int(store.query("SELECT COUNT(*) FROM sample WHERE design = ? AND metric = ?",
                            (design, metric))[0][0])
    step = max(1, -(-total // PLOT_SAMPLE))
    if step == 1:
        rows = store.query("SELECT value FROM sample WHERE design = ? AND metric = ?",
                           (design, metric))
    else:
        rows = store.query("SELECT value FROM sample WHERE design = ? AND metric = ? AND "
                           "rowid % ? = 0", (design, metric, step))
    return [float(r[0]) for r in rows], total


def _outcomes_all(store: ResultStore, design: str, metrics: list[str], days: int, users: int
                  ) -> tuple[dict[str, list[float]], dict[str, list[int]]]:
    """Per metric in ``metrics``: its mean count per user on each day, and its total count in
    each hour of the day, from the outcome rows summed over users (at most metrics x days x 24
    sums, kept by the store while it stores, or one pass over its largest table)."""
    by_day: dict[str, dict[int, float]] = {m: {} for m in metrics}
    by_hour: dict[str, dict[int, int]] = {m: {} for m in metrics}
    for metric, day, hour, n in store.outcome_sums(design):
        if metric in by_day:
            day_counts, hour_counts = by_day[metric], by_hour[metric]
            day_counts[int(day)] = day_counts.get(int(day), 0.0) + float(n)
            hour_counts[int(hour)] = hour_counts.get(int(hour), 0) + int(n)
    per_day = {m: [by_day[m].get(d, 0.0) / max(users, 1) for d in range(days)]
               for m in metrics}
    per_hour = {m: [by_hour[m].get(h, 0) for h in range(24)] for m in metrics}
    return per_day, per_hour


def _day_intervals(store: ResultStore, design: str, metrics: list[str], days: int,
                   users: int) -> dict[str, list[tuple[float | None, float | None]]]:
    """Per metric in ``metrics``: the 95 % interval of its mean count per user on each day
    (as a count metric's over the run: t over users, widened to Garwood with fewer than 10
    events), from the sums and sums of squares over users the store keeps."""
    from opspec.statistics import count_estimate_from_sums

    totals: dict[tuple[str, int], float] = {}
    for metric, day, _hour, n in store.outcome_sums(design):
        totals[(metric, int(day))] = totals.get((metric, int(day)), 0.0) + float(n)
    squares = {(m, int(d)): float(q) for m, d, q in store.outcome_day_squares(design)}
    out = {}
    for m in metrics:
        out[m] = []
        for d in range(days):
            e = count_estimate_from_sums(totals.get((m, d), 0.0), squares.get((m, d), 0.0),
                                         users)
            out[m].append((e.low, e.high))
    return out


def _activity_rates(store: ResultStore, design: str) -> list[dict[str, Any]]:
    """Per manual activity: offered, omission and error rates per offer with their intervals
    (:func:`opspec.evaluation.summary.summarise_activities`)."""
    return summarise_activities(store, design)


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


def _users_done(store: ResultStore, design: str) -> int:
    return int(store.query("SELECT COUNT(*) FROM replication WHERE design = ? AND "
                           "status = 'done'", (design,))[0][0])


# ------------------------------------------------------------------------ what is in words

def _with_selectors(store: ResultStore, design: str, spec: str | None, sha256: str | None
                    ) -> list[dict[str, Any]]:
    """The stored definitions; stores written before selectors were kept get them from the
    spec when it is still the file the run used."""
    definitions = [dict(d) for d in metric_definitions(store, design)]
    if not definitions or all("select" in d for d in definitions) or not spec:
        return definitions
    try:
        from opspec.evaluation.describe import metric_record
        from opspec.evaluation.plan import file_digest
        from opspec.xpdl.loader import load_spec

        if sha256 and file_digest(spec) != sha256:
            return definitions
        declared = {m.name: metric_record(m) for m in load_spec(spec).metrics}
    except Exception:  # noqa: BLE001 - a report without the detail is still a report
        return definitions
    return [{**declared.get(d["name"], {}), **{k: v for k, v in d.items() if v is not None}}
            for d in definitions]


def _drawn_values(store: ResultStore, design: str, names: Sequence[str]
                  ) -> dict[str, dict[str, list[float]]]:
    """Per drawn parameter, per subgroup (or all users), the values drawn for the users."""
    rows = store.query(
        "SELECT p.parameter, g.subgroup, p.value FROM person_parameter p JOIN person g ON "
        "g.design = p.design AND g.user = p.user WHERE p.design = ? ORDER BY p.rowid",
        (design,))
    out: dict[str, dict[str, list[float]]] = {n: {} for n in names}
    for name, group, value in rows:
        out.setdefault(str(name), {}).setdefault(str(group or "all users"), []).append(
            float(value))
    return out


def _population_part(store: ResultStore, model: Any, population: Mapping[str, Any] | None,
                     figures: Path, design: str) -> tuple[list[str], list[Any], list[Path],
                                                          list[str], list[str]]:
    """Paragraphs, tables, figures, captions and notes on the population: what the file
    declares, and who was drawn."""
    from opspec.evaluation import plots
    from opspec.evaluation.html import Table

    declared = model.population
    paragraphs = [("The simulated users are a population: each user's subgroup and some of "
                  "their parameters are drawn once per user, as declared below; the tables "
                  "after it show who was drawn.")]
    tables = [Table(("subgroup", "share", "parameter", "per-user distribution", "mean", "sd",
                     "5–95 %", "source"), tuple(variation_rows(declared)),
                    "Parameters that differ by person, as the user-model file declares them")]
    correlations = correlation_rows(declared)
    if correlations:
        tables.append(Table(("subgroup", "parameters", "stated", "copula r", "source"),
                            tuple(correlations),
                            "Correlations between a person's parameters (Gaussian copula)"))
    images: list[Path] = []
    captions: list[str] = []
    if population:
        if population.get("subgroups"):
            test = population.get("shares_test")
            tables.append(Table(SUBGROUP_HEADERS, tuple(subgroup_rows(population)),
                                "Users drawn per subgroup: realised share with its exact 95 % "
                                "interval, and the share asked for"
                                + (f" (chi-square test p = {test['p_value']:.3g})"
                                   if test else "")))
        tables.append(Table(PARAMETER_HEADERS, tuple(parameter_rows(population)),
                            "Parameters drawn per user (each user's value is stored with "
                            "their replication: person_parameter in results.sqlite)"))
        values = _drawn_values(store, design, list(population.get("parameters") or {}))
        order = list(population.get("subgroups") or {})      # as the file declares them
        values = {n: dict(sorted(v.items(), key=lambda kv: order.index(kv[0])
                                 if kv[0] in order else len(order))) for n, v in values.items()}
        images.append(plots.parameters_figure(values, figures / "population-parameters.png"))
        captions.append("The parameters drawn for the simulated users, one panel per "
                        "parameter, by subgroup (outline histograms, share of each "
                        "subgroup's users)")
    return paragraphs, tables, images, captions, population_notes(declared)


def _user_model_section(store: ResultStore, plan: Mapping[str, Any], figures: Path,
                        population: Mapping[str, Any] | None = None) -> Any:
    from opspec.evaluation.html import Section, Table

    ref = plan.get("user_model")
    if not ref:
        return Section("Who the simulated users are", paragraphs=(
            "No user model: the spec has no user lane, so no person is simulated.",))
    try:
        from opspec.evaluation.plan import file_digest
        from opspec.usermodels.loader import load_user_model

        stored = store.get("user_model_sha256")
        changed = bool(stored and Path(str(ref)).is_file()
                       and file_digest(str(ref)) != stored)
        model = load_user_model(str(ref))
    except Exception as error:  # noqa: BLE001 - say why, keep the rest of the report
        return Section("Who the simulated users are", paragraphs=(
            f"User model {ref}: its parameters cannot be listed here ({error}).",))
    paragraphs = [(f"User model {model.name} ({ref}). Every activity of the user's lane is "
                  "performed with these parameters; durations are in seconds of simulated "
                  "time.")]
    if changed:
        paragraphs.append(f"Warning: {ref} has changed since the run started; the table "
                          "shows the file as it is now, not necessarily what the run used.")
    tables = [Table(("activity", "duration", "errors", "source"),
                    tuple(user_model_rows(model)),
                    "User-model parameters per activity"
                    + (" (the typical user)" if model.population is not None else ""))]
    notes = user_model_notes(model)
    images: list[Path] = []
    captions: list[str] = []
    if model.population is not None:
        more, extra, images, captions, more_notes = _population_part(
            store, model, population, figures, str((plan.get("designs") or [{}])[0].get(
                "label", "A")))
        paragraphs += more
        tables += extra
        notes += more_notes
    return Section("Who the simulated users are", paragraphs=tuple(paragraphs),
                   tables=tuple(tables), images=tuple(images), captions=tuple(captions),
                   items=tuple(notes))


def _ci_words(summary: Mapping[str, Any], unit: str = "", *, percent: bool = False) -> str:
    low, high = summary.get("ci95") or [None, None]
    if low is None or high is None:
        return ""
    return (f" (95 % confidence interval {fmt(low, unit, percent=percent)} to "
            f"{fmt(high, unit, percent=percent)})")


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
    percent = is_rate(metric, s)
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


def _key_findings(users: int, days: float, metrics: Mapping[str, Mapping[str, Any]],
                  definitions: Sequence[Mapping[str, Any]],
                  monitors: Mapping[str, Mapping[str, Any]], design_name: str) -> list[str]:
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


def _population_findings(metrics: Mapping[str, Mapping[str, Any]],
                         population: Mapping[str, Any] | None) -> list[str]:
    """How users differ in sentences: per rate, how many users had any event and the
    percentiles of their own rates; per subgroup, the rates."""
    lines = []
    for name, s in metrics.items():
        own = s.get("per_user") or {}
        if not is_rate(name, s) or not own.get("users") or own.get("share_with_any") is None:
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
                 if is_rate(n, m) and m.get("value") is not None]
        if rates:
            lines.append(f"Subgroup {group} ({entry['users']:,} users, "
                         f"{fmt(entry['share'], percent=True)}): " + "; ".join(rates) + ".")
    return lines


# ------------------------------------------------------------------------------ the report

def _by_subgroup_section(metrics: Mapping[str, Any], population: Mapping[str, Any],
                         design: str, first: str, prefix: str) -> Any:
    from opspec.evaluation.html import Section, Table

    key = "metrics" if design == first else f"metrics_{design}"
    headers, rows = subgroup_metric_rows(metrics, population, key)
    return Section(f"{prefix}By subgroup", paragraphs=(
        ("Every metric over all users and over the users of each subgroup (in brackets the "
         "number of users), each with its 95 % confidence interval computed as for all "
         "users. A subgroup's interval is wider: it has fewer users."),),
        tables=(Table(headers, tuple(rows), "Metrics per subgroup: estimate [95 % CI]"),))


def _subgroup_rates(store: ResultStore, design: str, definition: Mapping[str, Any],
                    groups: Sequence[str]) -> dict[str, list[float]]:
    """Each user's own value of a ratio metric, over all users and per subgroup."""
    out = {"all users": [y / k for _, (y, k) in user_pairs(store, design, definition)
                         if k > 0]}
    for group in groups:
        members = subgroup_users(store, design, group)
        out[group] = [y / k for _, (y, k) in user_pairs(store, design, definition, members)
                      if k > 0]
    return out


def _design_sections(store: ResultStore, figures: Path, design: str, name: str, days: float,
                     users: int, metrics: Mapping[str, dict[str, Any]],
                     monitors: Mapping[str, Any], definitions: Sequence[Mapping[str, Any]],
                     prefix: str, population: Mapping[str, Any] | None = None,
                     first: str = "A") -> list[Any]:
    from opspec.evaluation import plots
    from opspec.evaluation.html import Section, Table

    sections: list[Any] = []
    # the estimates: the table, and the rates each on its own scale (same numbers)
    rates = [(words(n), s["value"], *(s["ci95"] or [s["value"], s["value"]]))
             for n, s in metrics.items() if is_rate(n, s) and s["value"] is not None]
    images, captions = [], []
    if rates:
        images.append(plots.rates_figure(rates, figures / f"{design}-rates.png"))
        captions.append("Outcome rates with 95 % confidence intervals, each on its own scale "
                        "(the same numbers as the table)")
    sections.append(Section(f"{prefix}Estimates", paragraphs=(
        ("Counts are per user over the whole run (sd, median and p95 are of the users' "
        "totals); durations are pooled over all observations; ratios are the sum of the "
        "numerator over the sum of the denominator over all users."),),
        tables=(Table(METRIC_HEADERS, tuple(metric_rows(metrics)),
                      f"Declared metrics of {name}: {users:,} simulated users × "
                      f"{span(days)} each"),),
        images=tuple(images), captions=tuple(captions)))
    if population and population.get("subgroups"):
        sections.append(_by_subgroup_section(metrics, population, design, first, prefix))

    # how users differ: each user's own value
    spread = per_user_rows(metrics)
    if spread:
        series: dict[str, Any] = {}
        units: dict[str, str] = {}
        shown = [d for d in definitions
                 if (s := metrics.get(d["name"])) is not None and s["kind"] != "count"
                 and (s.get("per_user") or {}).get("users")]
        # the figure gets a few numbers per metric (plots.user_distribution), worked out
        # one metric at a time from the users' values the summaries left on disk
        values = per_user_values(store, design, definitions)
        for d in shown:
            s = metrics[d["name"]]
            label = (f"{metric_label(d['name'], s)}, mean per user"
                     if s["kind"] == "duration" else metric_label(d["name"], s))
            units[label] = ("%" if is_rate(d["name"], s)
                            else (s.get("unit") or "s") if s["kind"] == "duration" else "")
            series[label] = plots.user_distribution(
                values.in_user_order(d["name"]), 100.0 if units[label] == "%" else 1.0)
        image = plots.per_user_figure(series, figures / f"{design}-per-user.png", units=units)
        groups = list((population or {}).get("subgroups") or {})
        spread_rows = distribution_rows(metrics)
        images = [image]
        captions = [("Distribution over users of each user's own value (a histogram per "
                     "metric, each on its own scale; the line is the mean over users)")]
        key = "metrics" if design == first else f"metrics_{design}"
        for group in groups:
            spread_rows += distribution_rows(
                (population or {})["subgroups"][group].get(key) or {}, group,
                informative=True)
        if groups:
            for d in definitions:
                s_ = metrics.get(d["name"])
                if s_ is None or not is_rate(d["name"], s_) or not (
                        s_.get("per_user") or {}).get("users"):
                    continue
                images.append(plots.subgroups_figure(
                    metric_label(d["name"], s_), _subgroup_rates(store, design, d, groups),
                    figures / f"{design}-{file_name(d['name'])}-by-subgroup.png", unit="%"))
                captions.append(f"Each user's own {words(d['name'])}, over the users of each "
                                "subgroup (outline histograms, share of the group's users)")
        sections.append(Section(f"{prefix}How users differ", paragraphs=(
            ("Each user's own rate or mean duration, over users: the spread shows how much "
            "one user's experience can differ from the average. 'Users with any' counts the "
            "users with at least one event (a count) or a rate above zero, with its exact "
            "(Clopper-Pearson) interval; p50, p90 and p99 are percentiles of the users' own "
            "values; the between-user sd of a proportion is the sd of the users' true rates "
            "once each user's binomial noise is taken out (about 0 when users differ only by "
            "chance)."),),
            tables=(Table(PER_USER_HEADERS, tuple(spread),
                          "Each user's own mean duration or ratio, over users"),
                    Table(DISTRIBUTION_HEADERS, tuple(spread_rows),
                          "Per-user distributions" + (", overall and by subgroup"
                                                      if groups else ""))),
            images=tuple(images), captions=tuple(captions)))

    # durations
    images, captions = [], []
    for d in definitions:
        s = metrics.get(d["name"])
        if d["kind"] != "duration" or s is None:
            continue
        values, total = _observations(store, design, d["name"])
        marks = {"mean": s.get("mean"), "median": s.get("median"), "p95": s.get("p95")}
        unit = s.get("unit") or "s"
        images.append(plots.latency_figure(d["name"], values,
                                           figures / f"{design}-{file_name(d['name'])}.png",
                                           marks=marks, total=total,
                                           label=metric_label(d["name"], s), unit=unit))
        caption = (f"Distribution of {metric_label(d['name'], s)}"
                   + (f" ({d['description'].rstrip('.')})" if d.get("description") else "")
                   + ": the share of observations done within x (left) and histogram "
                   "(right); mean, median and p95 marked")
        if total > len(values):
            caption += (f"; drawn from an even sample of {len(values):,} of the {total:,} "
                        "observations; mean, median and p95 are of all observations")
        else:
            caption += f" of all {total:,} observations"
        captions.append(caption)
    if images:
        sections.append(Section(f"{prefix}Durations", images=tuple(images),
                                captions=tuple(captions)))

    # counts over time
    counts = [d["name"] for d in definitions if d["kind"] == "count"]
    if counts:
        # one pass over the outcome table for all metrics, not two per metric (issue 20)
        per_day, hours = _outcomes_all(store, design, counts, max(1, round(days)), users)
        bands = _day_intervals(store, design, counts, max(1, round(days)), users)
        per_day = {words(n): v for n, v in per_day.items()}
        bands = {words(n): v for n, v in bands.items()}
        hours = {words(n): v for n, v in hours.items()}
        sections.append(Section(f"{prefix}Counts over time", images=(
            plots.over_days_figure(per_day, figures / f"{design}-days.png", bands=bands),
            plots.time_of_day_figure(hours, figures / f"{design}-hours.png")), captions=(
            ("Count outcomes per user, day by day: the mean over users (line) and its 95 % "
            "interval (band; t over users, widened to the exact Poisson interval on days "
            "with fewer than 10 events); each metric on its own scale, so rare outcomes are "
            "visible"),
            ("Count outcomes by hour of the day, all users and days (each metric on its own "
            "scale)"))))

    # the user's actions
    activity = _activity_rates(store, design)
    if activity:
        image = plots.activity_rates_figure(
            [(r["activity"], r["omission"], r["error"], r["omission_ci95"], r["error_ci95"])
             for r in activity], figures / f"{design}-activities.png")

        def rate(value: float, ci: Sequence[float | None]) -> str:
            return (f"{fmt(value, percent=True)} [{fmt(ci[0], percent=True)}, "
                    f"{fmt(ci[1], percent=True)}]")

        sections.append(Section(f"{prefix}The user's actions", paragraphs=(
            ("For each activity of the user's lane: how often it was asked of the user "
            "(offered), the share not done (omitted: an alarm not heard, a step forgotten) "
            "and the share done wrongly (a wrong button chosen), with 95 % intervals over "
            "users."),),
            tables=(Table(("activity", "offered", "omitted per offer [95 % CI]",
                           "wrong per offer [95 % CI]", "CI method"),
                          tuple((r["activity"], f"{r['offered']:,}",
                                 rate(r["omission"], r["omission_ci95"]),
                                 rate(r["error"], r["error_ci95"]), method_name(r))
                                for r in activity),
                          "Per-activity rates of the user's lane"),),
            images=(image,), captions=(
                ("The user's activities: omission and error rates per offer, in % of the "
                 "times each was asked for, with 95 % intervals (the same numbers as the "
                 "table)"),)))

    # hazards
    if monitors:
        sections.append(Section(f"{prefix}Hazards", paragraphs=(
            ("Safety properties the spec declares (opspec:Monitor), watched in every "
            "replication. The hazard is violations per user-day with a 95 % interval (the "
            "wider of the exact Poisson and the cluster-robust interval over users)."),),
            tables=(Table(MONITOR_HEADERS, tuple(monitor_rows(monitors)),
                          "Safety monitors the spec declares (opspec:Monitor)"),)))
    else:
        sections.append(Section(f"{prefix}Hazards", paragraphs=(
            (f"{name} declares no safety monitors (opspec:Monitor), so no hazards were "
            "watched. Declare one as an ExtendedAttribute of the spec's package, "
            "opspec:Monitor, with a property such as 'min_gap dispense 4h' (two dispenses "
            "never less than 4 hours apart), to have its violations counted here."),)))
    return sections


def _methods_section(summaries: Any, sections: Sequence[Any]) -> Any:
    """How every interval in the report was computed: each method that appears in it, with
    its recipe and references (the same words as ``--json`` and docs/evaluation.md), so the
    report stands on its own."""
    from opspec.evaluation.html import Section, Table
    from opspec.statistics.methods import METHODS, methods_in

    named = {m.name: m.id for m in METHODS.values()}
    shown = {named[row[i]] for section in sections for table in section.tables
             if "CI method" in table.headers
             for row in table.rows for i in [table.headers.index("CI method")]
             if i < len(row) and row[i] in named}
    used = [m for m in METHODS if m in shown or m in methods_in(summaries)]
    rows = tuple((METHODS[m].name, METHODS[m].definition, "; ".join(METHODS[m].references))
                 for m in used)
    return Section("How the intervals were computed", paragraphs=(
        ("Every interval is a two-sided 95 % confidence interval. The simulated users are the "
         "independent units: observations within one user are not independent (a slow walker "
         "is slow at every dose), so each metric is reduced to one pair (y, n) per user and "
         "the intervals are over users. The 'CI method' column of each table names the "
         "method below; an interval of something that cannot be negative is cut at zero. "
         "Medians and p95 of durations are of all pooled observations, by linear "
         "interpolation; per-user percentiles are of the users' own values."),),
        tables=(Table(("method", "definition", "references"), rows,
                      "The interval methods used in this report"),) if rows else ())


def write_report(store: ResultStore, summaries: Mapping[str, Summaries] | None = None, *,
                 template: str | Path | None = None, figures: str = "svg",
                 workers: int = 1) -> Path:
    """Write ``report.html``, ``report.md`` and ``figures/*.svg`` (or ``.pdf`` beside SVG
    twins, or ``.png``: ``figures``, :data:`opspec.evaluation.plots.FORMATS`) into the
    store's folder.

    ``summaries`` per design label (``metrics``, ``monitors``; ``difference`` under ``"B"``)
    are what the caller already computed; what is missing is computed here. ``template`` is
    a Jinja2 template to render the HTML with instead of the bundled one. The figures are
    drawn by up to ``workers`` processes side by side (:func:`.plots.drawn_by`).
    """
    from opspec.evaluation import plots
    from opspec.evaluation.html import write_html, write_markdown

    with plots.figure_format(figures):
        with plots.drawn_by(workers):
            title, sections = _report_sections(store, summaries)
        write_markdown(store.folder / "report.md", title, sections)
        return write_html(store.folder / "report.html", title, sections, template=template)


def _report_sections(store: ResultStore, summaries: Mapping[str, Summaries] | None
                     ) -> tuple[str, list[Any]]:
    from opspec.evaluation import plots
    from opspec.evaluation.html import Section, Table

    summaries = summaries or {}
    folder = store.folder
    figures = folder / "figures"
    plan: dict[str, Any] = store.get("plan") or {}
    days = float(plan.get("days", 1))
    designs = [d["label"] for d in plan.get("designs", [])] or ["A"]
    specs = {d["label"]: d["spec"] for d in plan.get("designs", [])}
    digests = {d["label"]: d.get("sha256") for d in plan.get("designs", [])}
    names = {label: Path(specs.get(label, "spec")).name for label in designs}
    if len(set(names.values())) < len(names):         # two files of the same name
        names = {label: specs.get(label, label) for label in designs}
    if len(set(names.values())) < len(names):         # a design compared with itself
        names = {label: f"{name} ({'first' if i == 0 else 'second'})"
                 for i, (label, name) in enumerate(names.items())}
    # a sweep (--sweep): its designs are the parameter's values, named by them; the
    # detailed sections describe the first value, the sweep's own sections the others
    sweep = summaries.get("sweep")
    if sweep is None and store.get("sweep"):
        from opspec.evaluation.sweep import Sweep, summarise_sweep

        sweep = summarise_sweep(store, Sweep.from_json(store.get("sweep")), days)
    detailed = designs[:1] if sweep else designs
    if sweep:
        names = {v["design"]: f"{sweep['parameter']} = {v['text']}" for v in sweep["values"]}
    done = {d: _users_done(store, d) for d in designs}
    failures = store.failures()

    per_design: dict[str, tuple[dict[str, Any], dict[str, Any], list[dict[str, Any]]]] = {}
    for design in detailed:
        given = summaries.get(design) or {}
        metrics = given.get("metrics")
        if metrics is None:
            metrics = summarise_design(store, design, days)
        monitors = given.get("monitors")
        if monitors is None:
            monitors = summarise_monitors(store, design, days)
        definitions = _with_selectors(store, design, specs.get(design), digests.get(design))
        per_design[design] = (metrics, monitors, definitions)

    given_a = summaries.get(designs[0]) or {}
    population = (given_a["population"] if "population" in given_a
                  else summarise_population(store, days, designs=detailed))

    sections: list[Any] = []
    metrics_a, monitors_a, definitions_a = per_design[designs[0]]
    findings = _key_findings(done.get(designs[0], 0), days, metrics_a, definitions_a,
                             monitors_a, names[designs[0]])
    findings += _population_findings(metrics_a, population)
    difference: dict[str, Any] | None = None
    if "B" in designs:
        difference = (summaries.get("B") or {}).get("difference")
        if difference is None:
            difference = compare_designs(store)
        differs = [n for n, d in difference.items() if d.get("significant")]
        findings.append(f"Compared with {names['B']} on the same users: "
                        + (f"{', '.join(differs)} differ (95 % intervals of the paired "
                           "differences exclude zero)." if differs
                           else "no metric differs (every 95 % interval of the paired "
                           "differences includes zero)."))
    if sweep:
        findings += [a["answer"] for a in sweep["targets"]]
        findings += [a["users_answer"] for a in sweep["targets"] if a.get("users_answer")]
    if failures:
        findings.append(f"{len(failures)} replication(s) failed and are left out of every "
                        "number (listed at the end).")
    sections.append(Section("Key findings", paragraphs=(findings[0],),
                            items=tuple(findings[1:])))

    total_users = plan.get("users")
    run_rows = [("specification", specs.get("A", "?"))]
    if "B" in specs:
        run_rows.append(("compared with", specs["B"]))
    if sweep:
        run_rows.append(("swept", f"{sweep['parameter']} = "
                         + ", ".join(v["text"] for v in sweep["values"])))
    finished = "; ".join(f"{done[d]:,} of {total_users:,}" + (f" ({names[d]})"
                                                              if len(designs) > 1 else "")
                         for d in designs) if isinstance(total_users, int) else str(done)
    run_rows += [("simulated users", f"{total_users:,}" if isinstance(total_users, int)
                  else str(total_users)),
                 ("simulated time per user", span(days)),
                 ("seed", str(plan.get("seed"))),
                 ("user model", str(plan.get("user_model") or "none")),
                 ("users finished", finished),
                 ("replications failed", str(len(failures))),
                 ("opspec version", str(store.get("opspec_version"))),
                 ("started", str(store.get("started")))]
    sections.append(Section("What was run", paragraphs=(
        "Each simulated user is an independent replication with their own random streams"
        + ("; the designs are compared on the same users (common random numbers)."
           if len(designs) > 1 else "."),), tables=(Table(("parameter", "value"),
                                                          tuple(run_rows)),)))
    if sweep:
        from opspec.evaluation.sweep import report_sections

        sections += report_sections(sweep, figures, done.get(designs[0], 0))

    for design in detailed:
        definitions = per_design[design][2]
        suffix = f" ({names[design]})" if len(detailed) > 1 else ""
        sections.append(Section(f"What each metric measures{suffix}", tables=(Table(
            ("metric", "kind", "definition"),
            tuple((d["name"], str(d["kind"]), describe_metric(d)) for d in definitions),
            "Metrics the spec declares (opspec:Metrics), computed from each user's trace"),)))
    sections.append(_user_model_section(store, plan, figures, population))

    for design in detailed:
        metrics, monitors, definitions = per_design[design]
        prefix = f"{names[design]}: " if len(detailed) > 1 or sweep else ""
        sections += _design_sections(store, figures, design, names[design], days,
                                     done.get(design, 0), metrics, monitors, definitions,
                                     prefix, population, designs[0])

    if difference is not None:
        # each panel names its metric as the other figures do (report latency, not its id)
        rows = [(metric_label(n, d), d["difference"],
                 *(d["ci95"] or [d["difference"], d["difference"]]))
                for n, d in difference.items() if d["difference"] is not None]
        units = {metric_label(n, d): "pp" if is_rate(n, d) else (d.get("unit") or "")
                 for n, d in difference.items()}
        compared = ((plots.comparison_figure(rows, figures / "comparison.png", units),)
                    if rows else ())
        headers: tuple[str, ...] = ("metric", names["A"], names["B"], "difference", "95 % CI",
                                    "CI method", "")
        sections.append(Section(f"{names['B']} compared with {names['A']}", paragraphs=(
            (f"Differences {names['B']} − {names['A']} per metric on the same simulated users "
            "(paired); 'differs' marks intervals that exclude zero."),),
            tables=(Table(headers, tuple(comparison_rows(difference))),),
            images=compared,
            captions=("Paired differences with 95 % CIs, each on its own scale",)
            if compared else ()))
        if population and population.get("subgroups"):
            headers, rows = subgroup_comparison_rows(population)
            sections.append(Section(f"{names['B']} compared with {names['A']}, by subgroup",
                                    paragraphs=(
                ("The same paired differences within each subgroup: a design change can "
                 "help one kind of user and not another. * marks intervals that exclude "
                 "zero."),), tables=(Table(headers, tuple(rows),
                                           "Paired differences B − A per subgroup "
                                           "[95 % CI]"),)))

    if plan.get("input_uncertainty"):      # the fitted model's parameter draws
        from opspec.evaluation.input_uncertainty import report_section

        sections.append(report_section(store, given_a, (summaries.get("B") or {}).get(
            "difference") if "B" in designs else None))

    if failures:
        from opspec.evaluation.failures import advice

        todo = advice(failures)
        sections.append(Section("Failed replications", paragraphs=(
            f"They are left out of every number above. {todo[:1].upper()}{todo[1:]}.",),
            tables=(Table(("specification", "user", "error"),
                          tuple((names.get(d, d), str(u), e) for d, u, e in failures[:200])),
                    )))

    sections.append(_methods_section([per_design, summaries], sections))

    return f"Evaluation of {Path(specs.get(designs[0], 'spec')).name}", sections
