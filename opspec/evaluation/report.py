"""The evaluation report: ``report.html`` (self-contained) and ``report.md`` with PNG figures,
built from the result store alone (so a resumed or re-reported run gives the same report).

Figures: each duration metric's distribution (ECDF and histogram), rates with their CIs,
count outcomes per day and by hour of day, per-activity omission and error rates, and with
two designs the paired differences.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from opspec.evaluation.plan import span
from opspec.evaluation.store import ResultStore
from opspec.evaluation.summary import (
    compare_designs,
    metric_definitions,
    summarise_design,
    summarise_monitors,
)
from opspec.evaluation.tables import (
    COMPARE_HEADERS,
    METRIC_HEADERS,
    MONITOR_HEADERS,
    PER_USER_HEADERS,
    comparison_rows,
    is_rate,
    metric_rows,
    monitor_rows,
    per_user_rows,
)

__all__ = ["write_report"]

# Figures show at most this many observations per metric (a deterministic, even thinning);
# the statistics always use all of them.
PLOT_SAMPLE = 50_000


def _observations(store: ResultStore, design: str, metric: str) -> list[float]:
    total = store.query("SELECT COUNT(*) FROM sample WHERE design = ? AND metric = ?",
                        (design, metric))[0][0]
    step = max(1, -(-int(total) // PLOT_SAMPLE))
    rows = store.query("SELECT value FROM sample WHERE design = ? AND metric = ? AND "
                       "rowid % ? = 0", (design, metric, step))
    return [float(r[0]) for r in rows]


def _per_day(store: ResultStore, design: str, metric: str, days: int, users: int
             ) -> list[float]:
    rows = dict(store.query("SELECT day, SUM(n) FROM outcome WHERE design = ? AND metric = ? "
                            "GROUP BY day", (design, metric)))
    return [float(rows.get(d, 0)) / max(users, 1) for d in range(days)]


def _by_hour(store: ResultStore, design: str, metric: str) -> list[int]:
    rows = dict(store.query("SELECT hour, SUM(n) FROM outcome WHERE design = ? AND "
                            "metric = ? GROUP BY hour", (design, metric)))
    return [int(rows.get(h, 0)) for h in range(24)]


def _activity_rates(store: ResultStore, design: str) -> list[tuple[str, float, float]]:
    rows = store.query("SELECT activity, SUM(offered), SUM(omitted), SUM(wrong) FROM activity "
                       "WHERE design = ? GROUP BY activity ORDER BY MIN(rowid)", (design,))
    return [(str(a), (om or 0) / off, (wr or 0) / off) for a, off, om, wr in rows if off]


def _users_done(store: ResultStore, design: str) -> int:
    return int(store.query("SELECT COUNT(*) FROM replication WHERE design = ? AND "
                           "status = 'done'", (design,))[0][0])


def write_report(store: ResultStore) -> Path:
    """Write ``report.html``, ``report.md`` and ``figures/*.png`` into the store's folder."""
    from opspec.evaluation import plots
    from opspec.evaluation.html import Section, Table, write_html, write_markdown

    folder = store.folder
    figures = folder / "figures"
    plan: dict[str, Any] = store.get("plan") or {}
    days = float(plan.get("days", 1))
    designs = [d["label"] for d in plan.get("designs", [])] or ["A"]
    specs = {d["label"]: d["spec"] for d in plan.get("designs", [])}
    sections = []

    done = {d: _users_done(store, d) for d in designs}
    failures = store.failures()
    run_rows = [("spec (A)", specs.get("A", "?"))]
    if "B" in specs:
        run_rows.append(("compared with (B)", specs["B"]))
    run_rows += [("users", str(plan.get("users"))), ("simulated time per user", span(days)),
                 ("seed", str(plan.get("seed"))),
                 ("user model", str(plan.get("user_model") or "none")),
                 ("replications done", ", ".join(f"{d}: {n}" for d, n in done.items())),
                 ("replications failed", str(len(failures))),
                 ("opspec", str(store.get("opspec_version"))),
                 ("started", str(store.get("started")))]
    sections.append(Section("Run", paragraphs=(
        ("Each simulated user is an independent replication with their own random streams; "
        "designs are compared on the same users (common random numbers). Intervals are 95 % "
        "confidence intervals over users (cluster-robust for pooled observations; see "
        "docs/evaluation.md)."),), tables=(Table(("parameter", "value"), tuple(run_rows)),)))

    for design in designs:
        metrics = summarise_design(store, design, days)
        for name, summary in metrics.items():
            summary["name"] = name
        title = "Metrics" if len(designs) == 1 else f"Metrics of design {design}"
        images: list[Path] = []
        captions: list[str] = []
        rates = [(name, s["value"], *(s["ci95"] or [None, None])) for name, s in metrics.items()
                 if is_rate(name, s) and s["value"] is not None]
        rates = [(n, v, lo if lo is not None else v, hi if hi is not None else v)
                 for n, v, lo, hi in rates]
        if rates:
            images.append(plots.rates_figure(rates, figures / f"{design}-rates.png"))
            captions.append("Outcome rates with 95 % confidence intervals")
        definitions = metric_definitions(store, design)
        for d in definitions:
            if d["kind"] == "duration":
                values = _observations(store, design, d["name"])
                images.append(plots.latency_figure(d["name"], values,
                                                   figures / f"{design}-{d['name']}.png"))
                captions.append(f"Distribution of {d['name']} (ECDF and histogram)")
        counts = [d["name"] for d in definitions if d["kind"] == "count"]
        if counts:
            users = done.get(design, 0)
            per_day = {c: _per_day(store, design, c, max(1, round(days)), users)
                       for c in counts}
            images.append(plots.over_days_figure(per_day, figures / f"{design}-days.png"))
            captions.append("Count outcomes per user, day by day")
            hours = {c: _by_hour(store, design, c) for c in counts}
            images.append(plots.time_of_day_figure(hours, figures / f"{design}-hours.png"))
            captions.append("Count outcomes by hour of day (all users and days)")
        activity = _activity_rates(store, design)
        activity_table: tuple[Table, ...] = ()
        if activity:
            images.append(plots.activity_rates_figure(activity,
                                                      figures / f"{design}-activities.png"))
            captions.append("User-lane activities: omission and error rates per offer")
            activity_table = (Table(("activity", "omitted per offer", "wrong per offer"),
                                    tuple((a, f"{o * 100:.2f} %", f"{w * 100:.2f} %")
                                          for a, o, w in activity),
                                    "Per-activity rates of the user lane"),)
        spread = per_user_rows(metrics)
        spread_table = (Table(PER_USER_HEADERS, tuple(spread), "How users differ: each "
                              "user's own mean duration or ratio, over users"),) if spread else ()
        monitors = summarise_monitors(store, design, days)
        monitor_table = (Table(MONITOR_HEADERS, tuple(monitor_rows(monitors)),
                               "Safety monitors the spec declares (opspec:Monitor): "
                               "violations per user-day with 95 % CI (the wider of the exact "
                               "Poisson and the cluster-robust interval over users)"),
                         ) if monitors else ()
        sections.append(Section(title, tables=(Table(METRIC_HEADERS,
                                                     tuple(metric_rows(metrics)),
                                                     "Declared metrics of the spec"),
                                               *monitor_table, *spread_table,
                                               *activity_table),
                                images=tuple(images), captions=tuple(captions)))

    if "B" in designs:
        difference = compare_designs(store)
        rows = [(name, d["difference"], *(d["ci95"] or [None, None]))
                for name, d in difference.items() if d["difference"] is not None]
        rows = [(n, v, lo if lo is not None else v, hi if hi is not None else v)
                for n, v, lo, hi in rows]
        units = {name: "pp" if is_rate(name, d) else (d.get("unit") or "")
                 for name, d in difference.items()}
        compared = ((plots.comparison_figure(rows, figures / "comparison.png", units),) if rows
                    else ())
        sections.append(Section("B compared with A", paragraphs=(
            ("Differences B − A per metric on the same simulated users (paired); 'differs' "
            "marks intervals that exclude zero."),),
            tables=(Table(COMPARE_HEADERS, tuple(comparison_rows(difference))),),
            images=compared,
            captions=("Paired differences with 95 % CIs",) if compared else ()))

    if failures:
        sections.append(Section("Failed replications", paragraphs=(
            "Run `opspec evaluate --resume --out <this folder>` to run them again.",),
            tables=(Table(("design", "user", "error"),
                          tuple((d, str(u), e) for d, u, e in failures[:200])),)))

    title = f"Evaluation of {Path(specs.get('A', 'spec')).name}"
    write_markdown(folder / "report.md", title, sections)
    return write_html(folder / "report.html", title, sections)
