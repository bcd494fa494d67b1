"""The report's sections on one design: its estimates (a table and each rate's figure), by
subgroup, how users differ (each user's own value), each duration's distribution, counts day
by day and by hour, the user's actions per activity, and its hazards; with what their figures
draw, read from the result store.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from opspec.evaluation.describe import can_do_wrongly
from opspec.evaluation.no_spread_notes import figure_marks, no_spread_note
from opspec.evaluation.plan import span
from opspec.evaluation.report_findings import metric_label, words
from opspec.evaluation.store import ResultStore
from opspec.evaluation.summary import (
    per_user_values,
    subgroup_users,
    summarise_activities,
    user_pairs,
)
from opspec.evaluation.tables import (
    DISTRIBUTION_HEADERS,
    METRIC_HEADERS,
    MONITOR_HEADERS,
    PER_USER_HEADERS,
    distribution_rows,
    fmt,
    in_percent,
    method_name,
    metric_rows,
    monitor_rows,
    one_user_note,
    per_user_rows,
    subgroup_metric_rows,
)
from opspec.files import file_name

__all__ = ["PLOT_SAMPLE", "AskedAhead", "ask_ahead", "design_sections"]

# Figures draw at most this many observations per metric (a deterministic, even thinning,
# said in the caption); the statistics and the marks in the figure always use all of them.
PLOT_SAMPLE = 50_000


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


def _per_user_intervals(metrics: Mapping[str, Mapping[str, Any]]) -> str:
    """Why a metric has one interval under Estimates and another under How users differ:
    they are of two quantities, by two methods (the same words as docs/evaluation.md)."""
    text = ("'95 % CI of that mean (t)' is a confidence interval of the mean of the users' "
            "own values, every user counting once, by Student's t over those values; it is "
            "not the interval under Estimates, which is of the pooled estimate (Σ numerator "
            "/ Σ denominator over all users, a user with more observations weighing more) "
            "and, for a proportion, Wilson's interval on the effective number of trials, so "
            "one metric has two different intervals.")
    flat = [name for name, s in metrics.items() if s["kind"] != "count"
            and s.get("ci95_method") == "wilson-neff"
            and (low := ((s.get("per_user") or {}).get("ci95") or [None])[0]) is not None
            and low == (s["per_user"]["ci95"] or [None, None])[1]]
    if flat:
        text += (f" Every user had the same {' and the same '.join(flat)}, so the t interval "
                 "of their mean has no width: that is no bound on the rate, whose interval "
                 "is the one under Estimates.")
    return text


def _noted(summaries: Any) -> tuple[str, ...]:
    """The note on a table's marked intervals (:mod:`.no_spread_notes`), as a paragraph."""
    note = no_spread_note(summaries)
    return (note,) if note else ()


def _by_subgroup_section(metrics: Mapping[str, Any], population: Mapping[str, Any],
                         design: str, first: str, prefix: str) -> Any:
    from opspec.evaluation.html import Section, Table

    key = "metrics" if design == first else f"metrics_{design}"
    headers, rows = subgroup_metric_rows(metrics, population, key)
    shown = [*metrics.values(), *(s for g in (population.get("subgroups") or {}).values()
                                  for s in (g.get(key) or {}).values())]
    return Section(f"{prefix}By subgroup", paragraphs=(
        ("Every metric over all users and over the users of each subgroup (in brackets the "
         "number of users), each with its 95 % confidence interval computed as for all "
         "users. A subgroup's interval is wider: it has fewer users."), *_noted(shown)),
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


def _count_series(store: ResultStore, design: str, counts: list[str], days: float,
                  users: int) -> tuple[dict[str, Any], ...]:
    """What the counts-over-time figures draw of the count metrics ``counts``, keyed by
    their words: the mean per user on each day, its interval, the total in each hour, and
    what each day's interval of no width says (:func:`no_spread`, None for the others)."""
    from opspec.statistics.no_spread import no_spread

    # one pass over the outcome table for all metrics, not two per metric (issue 20)
    per_day, hours = _outcomes_all(store, design, counts, max(1, round(days)), users)
    bands = _day_intervals(store, design, counts, max(1, round(days)), users)
    return ({words(n): v for n, v in per_day.items()}, {words(n): v for n, v in bands.items()},
            {words(n): v for n, v in hours.items()},
            {words(n): [no_spread(day, users) for day in v] for n, v in bands.items()})


def _day_marks(series: tuple[dict[str, Any], ...]) -> dict[str, Any]:
    """How the days' intervals of no width from users all alike are marked in the figure
    (:func:`.no_spread_notes.figure_marks`), and so in its caption."""
    return figure_marks({name: [{"ci95_no_spread": alike} for alike in days]
                         for name, days in series[3].items()})


def _count_figures(series: tuple[dict[str, Any], ...], figures: Path, design: str
                   ) -> tuple[Path, Path]:
    from opspec.evaluation import plots

    per_day, bands, hours, _ = series
    return (plots.over_days_figure(per_day, figures / f"{design}-days.png", bands=bands,
                                   **_day_marks(series)),
            plots.time_of_day_figure(hours, figures / f"{design}-hours.png"))


def _never_wrong(activity: list[dict[str, Any]], user_model: Any) -> frozenset[str]:
    """The activities with no error rate to show: the run's user model has no wrong action
    for them, so 0 % is by construction and its interval (0 to 2 % at 187 offers) would read
    as a measured error rate; one counted anyway (a model file changed since) is shown."""
    if user_model is None:
        return frozenset()
    return frozenset(r["activity"] for r in activity if r["error"] == 0
                     and can_do_wrongly(user_model, r["activity"]) is False)


def _activity_figure(activity: list[dict[str, Any]], figures: Path, design: str,
                     never: frozenset[str] = frozenset()) -> Path:
    from opspec.evaluation import plots

    return plots.activity_rates_figure(
        [(r["activity"], r["omission"], None if r["activity"] in never else r["error"],
          r["omission_ci95"], r["error_ci95"]) for r in activity],
        figures / f"{design}-activities.png")


@dataclass(frozen=True)
class AskedAhead:
    """What :func:`ask_ahead` computed of one design and the figures it asked for: the
    counts-over-time figures (None without count metrics), the rows of the user's actions
    and their figure (None without activities), and the note on the days' intervals of no
    width from users all alike (None without one)."""

    counts: tuple[Path, Path] | None
    activity: list[dict[str, Any]]
    activity_image: Path | None
    counts_note: str | None = None


def ask_ahead(store: ResultStore, figures: Path, design: str, days: float, users: int,
              definitions: Sequence[Mapping[str, Any]], *, user_model: Any = None
              ) -> AskedAhead:
    """Ask for the figures of ``design``'s sections that need neither the sample index nor
    the summaries (counts over time, the user's actions: what the store keeps of the outcomes
    and activities), the same :func:`design_sections` asks for (``user_model``: the run's,
    as it is given). Everything is read before the first figure is asked for: a read that
    fails leaves nothing asked."""
    counts = [d["name"] for d in definitions if d["kind"] == "count"]
    series = _count_series(store, design, counts, days, users) if counts else None
    activity = _activity_rates(store, design)
    image = (_activity_figure(activity, figures, design, _never_wrong(activity, user_model))
             if activity else None)
    return AskedAhead(_count_figures(series, figures, design) if series is not None else None,
                      activity, image,
                      _day_marks(series).get("no_spread_note") if series is not None else None)


def design_sections(store: ResultStore, figures: Path, design: str, name: str, days: float,
                    users: int, metrics: Mapping[str, dict[str, Any]],
                    monitors: Mapping[str, Any], definitions: Sequence[Mapping[str, Any]],
                    prefix: str, population: Mapping[str, Any] | None = None,
                    first: str = "A", ahead: AskedAhead | None = None, *,
                    user_model: Any = None) -> list[Any]:
    """The sections on ``design`` (``name`` in their words; ``prefix`` before each title when
    the report describes several designs), in the report's order, their figures drawn into
    ``figures``. ``first`` is the design whose subgroup summaries are ``metrics`` in
    ``population`` (the others': ``metrics_<label>``). ``ahead``: what :func:`ask_ahead`
    computed and asked for of ``design`` with the same store, definitions and users (its
    figures are not asked for again). ``user_model``: the run's, when known
    (:func:`.report_users.user_model_as_run`), to leave out the error rate of an activity it
    cannot do wrongly."""
    from opspec.evaluation import plots
    from opspec.evaluation.html import Section, Table

    sections: list[Any] = []
    # the estimates: the table, and the rates each on its own scale (same numbers)
    rates = [(words(n), s["value"], *(s["ci95"] or [s["value"], s["value"]]))
             for n, s in metrics.items() if in_percent(s) and s["value"] is not None]
    images, captions = [], []
    if rates:
        images.append(plots.rates_figure(rates, figures / f"{design}-rates.png"))
        captions.append("Outcome rates with 95 % confidence intervals, each on its own scale "
                        "(the same numbers as the table)")
    sections.append(Section(f"{prefix}Estimates", paragraphs=(
        ("Counts are per user over the whole run (sd, median and p95 are of the users' "
        "totals); durations are pooled over all observations; ratios are the sum of the "
        "numerator over the sum of the denominator over all users."),
        *_noted(metrics.values()), *filter(None, [one_user_note(metrics, users)])),
        tables=(Table(METRIC_HEADERS, tuple(metric_rows(metrics)),
                      f"Declared metrics of {name}: {users:,} simulated "
                      f"user{'' if users == 1 else 's'} × "
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
            units[label] = ("%" if in_percent(s)
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
                if s_ is None or not in_percent(s_) or not (
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
            "chance)."), _per_user_intervals(metrics),
            *_noted(s.get("per_user") for s in metrics.values())),
            tables=(Table(PER_USER_HEADERS, tuple(spread),
                          "Each user's own mean duration or ratio, over users: the mean of "
                          "their values (every user counting once) with its t interval"),
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
        if ahead is not None and ahead.counts is not None:
            drawn, alike = ahead.counts, ahead.counts_note
        else:
            counted = _count_series(store, design, counts, days, users)
            drawn = _count_figures(counted, figures, design)
            alike = _day_marks(counted).get("no_spread_note")
        sections.append(Section(f"{prefix}Counts over time", images=drawn, captions=(
            ("Count outcomes per user, day by day: the mean over users (line) and its 95 % "
            "interval (band; t over users, widened to the exact Poisson interval on days "
            "with fewer than 10 events); each metric on its own scale, so rare outcomes are "
            "visible" + (f". {alike}" if alike else "")),
            ("Count outcomes by hour of the day, all users and days (each metric on its own "
            "scale)"))))

    # the user's actions
    if ahead is not None:
        activity, image = ahead.activity, ahead.activity_image
        never = _never_wrong(activity, user_model)
    else:
        activity = _activity_rates(store, design)
        never = _never_wrong(activity, user_model)
        image = _activity_figure(activity, figures, design, never) if activity else None
    if activity:

        def rate(value: float, ci: Sequence[float | None]) -> str:
            return (f"{fmt(value, percent=True)} [{fmt(ci[0], percent=True)}, "
                    f"{fmt(ci[1], percent=True)}]")

        paragraph = ("For each activity of the user's lane: how often it was asked of the user "
                     "(offered), the share not done (omitted: an alarm not heard, a step "
                     "forgotten) and the share done wrongly (a wrong button chosen), with 95 % "
                     "intervals over users. Both are per offer, re-offers included: a choice "
                     "offered again after a wrong button counts each time, so a rate per "
                     "offer is not the user model's probability per workflow instance "
                     "(per dose of a dispenser).")
        caption = ("The user's activities: omission and error rates per offer, in % of the "
                   "times each was asked for, with 95 % intervals (the same numbers as the "
                   "table")
        if never:
            paragraph += (" '–': the user model has no wrong action (a wrong choice or a "
                          "slip) for the activity, so it cannot be done wrongly and there is "
                          "no error rate to estimate.")
            caption += "; '–' where the user model has no wrong action, as in the table"
        sections.append(Section(f"{prefix}The user's actions", paragraphs=(paragraph,),
            tables=(Table(("activity", "offered", "omitted per offer [95 % CI]",
                           "wrong per offer [95 % CI]", "CI method"),
                          tuple((r["activity"], f"{r['offered']:,}",
                                 rate(r["omission"], r["omission_ci95"]),
                                 "–" if r["activity"] in never
                                 else rate(r["error"], r["error_ci95"]), method_name(r))
                                for r in activity),
                          "Per-activity rates of the user's lane"),),
            images=(image,), captions=(caption + ")",)))

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

