"""Plain-text tables of an evaluation's results (the terminal summary and the report's tables)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import IO, Any

from opspec.evaluation.no_spread_notes import no_spread_note, with_mark
from opspec.evaluation.plan import span
from opspec.properties.language import clock
from opspec.statistics.methods import METHODS, methods_in

__all__ = ["comparison_rows", "difference_text", "distribution_rows", "fmt", "in_percent", "method_legend",
           "method_name", "metric_rows", "monitor_rows", "no_interval_reason", "one_user_note",
           "parameter_rows", "per_user_rows", "points", "print_summary", "signed",
           "subgroup_comparison_rows", "subgroup_metric_rows", "subgroup_rows", "table"]

METRIC_HEADERS = ("metric", "kind", "estimate", "95 % CI", "CI method", "sd", "median", "p95",
                  "users", "pooled")
#: The mean of the users' own values, every user counting once, and its Student t interval
#: over users: not the pooled estimate of METRIC_HEADERS nor its interval, hence the words
PER_USER_HEADERS = ("metric", "users", "mean of users' values", "sd",
                    "95 % CI of that mean (t)", "median", "p95")
COMPARE_HEADERS = ("metric", "A", "B", "B − A", "95 % CI", "CI method", "verdict")
MONITOR_HEADERS = ("monitor", "violations", "users affected", "95 % CI (exact)",
                   "per user-day", "95 % CI", "CI method", "first violation")
SUBGROUP_HEADERS = ("subgroup", "users", "share", "asked", "95 % CI (exact)")
DISTRIBUTION_HEADERS = ("metric", "users", "users with any", "95 % CI (exact)", "p50", "p90",
                        "p99", "between-user sd")
PARAMETER_HEADERS = ("parameter", "subgroup", "users", "mean", "sd", "p5", "median", "p95")


def fmt(value: Any, unit: str = "", *, percent: bool = False) -> str:
    """A number for people: 4 significant digits, a unit, or a percentage."""
    if value is None:
        return "–"
    if percent:
        return f"{value * 100:.2f} %"
    if isinstance(value, float):
        text = f"{value:.4g}" if abs(value) < 1e6 else f"{value:.3e}"
    else:
        text = str(value)
    return f"{text} {unit}".rstrip()


def in_percent(summary: Mapping[str, Any]) -> bool:
    """Whether a metric's summary (or a difference of it) is shown in percent: a ratio the
    spec declares a proportion (``Proportion="true"``, the summary's ``proportion``), the
    rule of ``opspec run`` (:mod:`.run_metrics_text`); never from its name or its numbers
    (``alarms_per_dose`` is 4 of 4 in some runs, and is no proportion). A summary of a store
    written before the declaration was kept has no ``proportion``: a plain number, as its
    interval is a ratio's (docs/evaluation.md, Declared proportions)."""
    return summary.get("kind") == "ratio" and summary.get("proportion") is True


def _ci(summary: Mapping[str, Any], unit: str = "", *, percent: bool = False) -> str:
    """``[low, high]``, marked when it has no width because its few users were all alike
    (:mod:`.no_spread_notes`)."""
    low, high = (summary.get("ci95") or [None, None])
    if low is None or high is None:
        return "–"
    return with_mark(f"[{fmt(low, unit, percent=percent)}, {fmt(high, unit, percent=percent)}]",
                     summary)


def method_name(summary: Mapping[str, Any], key: str = "ci95_method") -> str:
    """The short name of the method of a summary's interval (``–`` without one)."""
    method = METHODS.get(summary.get(key) or "")
    return method.name if method else "–"


def _count(value: Any) -> str:
    """A pooled total: a whole number without ``.0``."""
    return "–" if value is None else (f"{value:g}" if isinstance(value, float)
                                      and not value.is_integer() else str(int(value)))


def metric_rows(metrics: Mapping[str, Mapping[str, Any]]) -> list[tuple[str, ...]]:
    """One row per metric. ``users``: the simulated users the estimate is over; ``pooled``:
    what was pooled over them — the events of a count, the observations of a duration, the
    numerator of the denominator of a ratio."""
    rows: list[tuple[str, ...]] = []
    for name, s in metrics.items():
        kind = s["kind"]
        users = _count(s.get("users"))
        # sd: of the users' totals for a count, of all observations for a duration
        if kind == "count":
            rows.append((name, "count", f"{fmt(s['mean'])} per user", _ci(s), method_name(s),
                         fmt(s["sd"]), fmt(s["median"]), fmt(s["p95"]), users,
                         f"{s['total']} events"))
        elif kind == "duration":
            unit = s.get("unit") or "s"
            rows.append((name, "duration", fmt(s["mean"], unit), _ci(s, unit), method_name(s),
                         fmt(s["sd"], unit), fmt(s["median"], unit), fmt(s["p95"], unit),
                         users, f"{s['n']} obs."))
        else:
            percent = in_percent(s)
            pooled = (f"{_count(s.get('numerator_total'))} of "
                      f"{_count(s.get('denominator_total'))}"
                      if s.get("denominator_total") is not None else "–")
            rows.append((name, "ratio", fmt(s["value"], percent=percent),
                         _ci(s, percent=percent), method_name(s), "–", "–", "–", users,
                         pooled))
    return rows


def one_user_note(metrics: Mapping[str, Mapping[str, Any]], users: int) -> str | None:
    """Why an evaluation of one user shows '–' for some intervals: the t interval needs the
    spread between users (the exact Poisson and binomial ones do not); None otherwise."""
    if users >= 2:
        return None
    bare = [name for name, s in metrics.items()
            if not s.get("ci95") or None in s["ci95"]]
    if not bare:
        return None
    return (f"– (no interval) for {', '.join(bare)}: one simulated user shows no spread "
            "between users to compute it from; evaluate two users or more (--users N, a few "
            "hundred for narrow intervals).")


def _users(n: int) -> str:
    return f"{n} user" if n == 1 else f"{n} users"


def method_legend(summaries: Any, keys: Sequence[str] | None = ("ci95_method",)
                  ) -> list[str]:
    """One line per interval method used in ``summaries`` (under the names ``keys``; None:
    any): its name, what it is and where it comes from (the full recipe is in ``--json``
    and the report)."""
    lines = []
    for method_id in methods_in(summaries, keys):
        m = METHODS[method_id]
        lines.append(f"  {m.name}: {m.summary} "
                     f"({m.cited})")
    return lines


def per_user_rows(metrics: Mapping[str, Mapping[str, Any]]) -> list[tuple[str, ...]]:
    """Durations and ratios over users: the spread of each user's own value."""
    rows: list[tuple[str, ...]] = []
    for name, s in metrics.items():
        per_user = s.get("per_user")
        if not per_user or not per_user.get("users"):
            continue
        unit = (s.get("unit") or "s") if s["kind"] == "duration" else ""
        percent = in_percent(s)
        rows.append((f"{name} ({'mean per user' if unit else 'per user'})",
                     str(per_user["users"]), fmt(per_user["mean"], unit, percent=percent),
                     fmt(per_user["sd"], unit, percent=percent),
                     _ci(per_user, unit, percent=percent),
                     fmt(per_user["median"], unit, percent=percent),
                     fmt(per_user["p95"], unit, percent=percent)))
    return rows


def monitor_rows(monitors: Mapping[str, Mapping[str, Any]]) -> list[tuple[str, ...]]:
    """The spec's monitors: violations, users affected (share), hazard per user-day."""
    rows: list[tuple[str, ...]] = []
    for name, m in monitors.items():
        first = m.get("first")
        where = (f"user {first['user']}, {clock(first['time'])}" if first
                 and first.get("time") is not None else "–")
        share = fmt(m.get("share_affected"), percent=True)
        affected = f"{m['users_affected']} of {m['users']} ({share})"
        # the share's exact interval (docs/evaluation.md, Monitors): 0 of 50 users is not
        # "nobody", but at most 7.11 %
        low, high = m.get("share_affected_ci95") or (None, None)
        exact = ("–" if low is None or high is None
                 else f"[{fmt(low, percent=True)}, {fmt(high, percent=True)}]")
        rows.append((name, str(m["violations"]), affected, exact, fmt(m["per_user_day"]),
                     _ci(m), method_name(m), where))
    return rows


def _estimate(name: str, s: Mapping[str, Any]) -> str:
    """One metric's estimate with its interval in one cell: ``0.36 % [0.33 %, 0.39 %]``."""
    kind = s["kind"]
    percent = in_percent(s)
    unit = (s.get("unit") or "s") if kind == "duration" else ""
    value = s.get("value") if kind == "ratio" else s.get("mean")
    ci = _ci(s, unit, percent=percent)
    return f"{fmt(value, unit, percent=percent)} {ci}" if ci != "–" else fmt(
        value, unit, percent=percent)


def subgroup_rows(population: Mapping[str, Any]) -> list[tuple[str, ...]]:
    """Per subgroup: users, realised share, the share the model asks for, exact interval."""
    rows: list[tuple[str, ...]] = []
    for name, g in (population.get("subgroups") or {}).items():
        low, high = g.get("share_ci95") or [None, None]
        rows.append((name, str(g["users"]), fmt(g["share"], percent=True),
                     fmt(g.get("expected_share"), percent=True),
                     f"[{fmt(low, percent=True)}, {fmt(high, percent=True)}]"
                     if low is not None else "–"))
    return rows


def subgroup_metric_rows(metrics: Mapping[str, Mapping[str, Any]],
                         population: Mapping[str, Any], key: str = "metrics"
                         ) -> tuple[tuple[str, ...], list[tuple[str, ...]]]:
    """Headers and rows: every metric over all users and per subgroup (estimate [95 % CI])."""
    groups = population.get("subgroups") or {}
    headers = ("metric", "all users", *(f"{n} ({g['users']})" for n, g in groups.items()))
    rows = []
    for name, s in metrics.items():
        cells = [_estimate(name, s)]
        for g in groups.values():
            own = (g.get(key) or {}).get(name)
            cells.append(_estimate(name, own) if own else "–")
        rows.append((name, *cells))
    return headers, rows


def subgroup_comparison_rows(population: Mapping[str, Any]
                             ) -> tuple[tuple[str, ...], list[tuple[str, ...]]]:
    """Headers and rows: the paired difference B − A of each metric per subgroup."""
    groups = population.get("subgroups") or {}
    names: list[str] = []
    for g in groups.values():
        names += [n for n in g.get("difference") or {} if n not in names]
    headers = ("metric", *groups)
    rows = []
    for name in names:
        cells = []
        for g in groups.values():
            d = (g.get("difference") or {}).get(name)
            if not d:
                cells.append("–")
                continue
            _, _, diff, ci, _, _, mark = comparison_rows({name: d})[0]
            cells.append(f"{diff} {ci}{' *' if mark else ''}")
        rows.append((name, *cells))
    return headers, rows


def distribution_rows(metrics: Mapping[str, Mapping[str, Any]], label: str = "", *,
                      informative: bool = False) -> list[tuple[str, ...]]:
    """How the users' own values are spread: users with at least one event (count) or a
    non-zero rate (ratio), with its exact interval, and percentiles of the per-user values.
    ``informative``: only counts some users have and others not (and ratios, durations)."""
    rows: list[tuple[str, ...]] = []
    for name, s in metrics.items():
        kind = s["kind"]
        own = s if kind == "count" else (s.get("per_user") or {})
        if not own.get("users"):
            continue
        if informative and kind == "count" and own.get("share_with_any") in (0.0, 1.0):
            continue
        percent = in_percent(s)
        unit = (s.get("unit") or "s") if kind == "duration" else ""
        share = own.get("share_with_any")
        if share is not None:
            low, high = own.get("share_with_any_ci95") or [None, None]
            anyone = f"{own['users_with_any']} ({fmt(share, percent=True)})"
            interval = f"[{fmt(low, percent=True)}, {fmt(high, percent=True)}]"
        else:
            anyone = interval = "–"
        what = {"count": "total per user", "duration": "mean per user",
                "ratio": "per user"}[kind]
        rows.append((f"{name} ({what})" + (f" – {label}" if label else ""), str(own["users"]),
                     anyone, interval,
                     *(fmt(own.get(p), unit, percent=percent)
                       for p in ("median", "p90", "p99")),
                     fmt(own.get("between_user_sd"), percent=percent)
                     if own.get("between_user_sd") is not None else "–"))
    return rows


def parameter_rows(population: Mapping[str, Any]) -> list[tuple[str, ...]]:
    """The parameters drawn per user: over all users, then per subgroup."""
    rows: list[tuple[str, ...]] = []
    groups = population.get("subgroups") or {}
    for name, overall in (population.get("parameters") or {}).items():
        for label, stats in [("all users", overall),
                             *((g, e["parameters"].get(name)) for g, e in groups.items())]:
            if not stats or not stats.get("users"):
                continue
            rows.append((name, label, str(stats["users"]),
                         *(fmt(stats.get(k)) for k in ("mean", "sd", "p5", "median", "p95"))))
    return rows


def points(value: Any) -> str:
    """A difference of two proportions in percentage points: ``-0.54 pp``."""
    return "–" if value is None else f"{value * 100:+.2f} pp"


def signed(value: Any, unit: str = "") -> str:
    """A difference B − A as :func:`fmt` writes a number, with its sign: ``+0.7378``,
    ``-12.5 s`` (the levels A and B carry none; a difference without one read as a level);
    no difference at all is ``0``."""
    if value is None:
        return "–"
    value = float(value)
    text = ("0" if value == 0 else f"{value:+.4g}" if abs(value) < 1e6
            else f"{value:+.3e}")
    return f"{text} {unit}".rstrip()


def difference_text(value: Any, unit: str = "", *, percent: bool = False) -> str:
    """A difference as the tables and the comparison figure write it: in percentage points
    for a proportion, else signed in its unit."""
    return points(value) if percent else signed(value, unit)


#: The CI method cell of a difference of durations without an interval: on common random
#: numbers fewer than 2 users' values differed between the designs, and the paired interval
#: cannot be estimated from them (opspec.statistics.paired_difference; docs/evaluation.md)
NO_DURATION_INTERVAL = "none: fewer than 2 users differ"


def no_interval_reason(d: Mapping[str, Any]) -> str | None:
    """Why a paired difference ``d`` has no interval, in a table cell's words; None when it
    has one (or no difference either)."""
    low, high = d.get("ci95") or [None, None]
    if d.get("difference") is None or (low is not None and high is not None):
        return None
    if (d.get("users") or 0) < 2:
        return "none: fewer than 2 users"
    return NO_DURATION_INTERVAL if d.get("kind") == "duration" else None


def comparison_rows(difference: Mapping[str, Mapping[str, Any]]) -> list[tuple[str, ...]]:
    rows: list[tuple[str, ...]] = []
    for name, d in difference.items():
        percent = in_percent(d)
        unit = "" if percent else (d.get("unit") or "")
        diff = difference_text(d["difference"], unit, percent=percent)
        low, high = d.get("ci95") or [None, None]
        ci = ("–" if low is None or high is None else
              with_mark(f"[{difference_text(low, unit, percent=percent)}, "
                        f"{difference_text(high, unit, percent=percent)}]", d))
        rows.append((name, fmt(d["a"], unit, percent=percent),
                     fmt(d["b"], unit, percent=percent), diff, ci,
                     no_interval_reason(d) or method_name(d),
                     "differs" if d["significant"] else ""))
    return rows


def table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h)
              for i, h in enumerate(headers)]
    line = "  ".join(h.ljust(w) for h, w in zip(headers, widths, strict=True)).rstrip()
    out = [line, "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip()
            for r in rows]
    return out


def print_summary(out: IO[str], plan: Any, metrics: Mapping[str, Any],
                  compare: Mapping[str, Any] | None, outcome: Any,
                  failures: Sequence[tuple[str, int, str]], workers: int,
                  monitors: Mapping[str, Any] | None = None,
                  population: Mapping[str, Any] | None = None) -> None:
    design = plan.design("A")
    print(f"opspec evaluate: {design.spec}, {_users(plan.users)} x {span(plan.days)}, seed "
          f"{plan.seed}, user model {plan.user_model or 'none'}", file=out)
    if getattr(plan, "run_inputs", None):
        from opspec.run_inputs import RunInputs

        print(f"run inputs per user: {RunInputs.from_json(plan.run_inputs).describe()}",
              file=out)
    count = outcome.done + outcome.failed
    ran = (f"{count} replication{'' if count == 1 else 's'} in {outcome.wall_s:.1f} s on "
           f"{workers} worker(s)")
    if outcome.skipped:
        ran += f" ({outcome.skipped} already stored)"
    print(ran, file=out)
    if failures:
        planned = (plan.users + plan.input_uncertainty * plan.users_per_draw) * len(
            plan.designs)
        print(f"{len(failures)} of {planned} replications FAILED (listed below); every "
              "number here is of the complete replications only", file=out)
    print(file=out)
    for line in table(METRIC_HEADERS, metric_rows(metrics)):
        print(line, file=out)
    if monitors:
        print("\nmonitors (opspec:Monitor in the spec; violations per user-day):", file=out)
        for line in table(MONITOR_HEADERS, monitor_rows(monitors)):
            print(line, file=out)
    if compare is not None and compare.get("monitors"):
        print("\nmonitors of B:", file=out)
        for line in table(MONITOR_HEADERS, monitor_rows(compare["monitors"])):
            print(line, file=out)
    if population:
        _print_population(out, metrics, population)
    if compare is not None:
        print(f"\ncompared with B = {compare['spec']} (same users, paired; 'differs': the "
              "95 % interval excludes 0):", file=out)
        for line in table(COMPARE_HEADERS, comparison_rows(compare["difference"])):
            print(line, file=out)
        if population and population.get("subgroups"):
            print("\nB − A per subgroup (paired; * the 95 % interval excludes 0):", file=out)
            for line in table(*subgroup_comparison_rows(population)):
                print(line, file=out)
    if failures:
        from opspec.evaluation.failures import advice, kind_of

        kinds: dict[str, int] = {}
        for _, _, error in failures:
            kinds[kind_of(error)] = kinds.get(kind_of(error), 0) + 1
        print(f"\n{len(failures)} replication(s) failed ("
              + ", ".join(f"{n} {k}" for k, n in sorted(kinds.items())) + "):", file=out)
        for design_label, user, error in failures[:10]:
            print(f"  {design_label}/{user}: {error}", file=out)
        if len(failures) > 10:
            print(f"  … and {len(failures) - 10} more", file=out)
        print(advice(failures), file=out)
    if bare := one_user_note(metrics, plan.users):
        print(f"\n{bare}", file=out)
    # what a marked interval means, once for every table above
    note = no_spread_note(_shown(metrics, compare, population))
    if note:
        print(f"\n{note}", file=out)
    # the intervals the tables above show (the exact shares of users only with a population)
    legend = method_legend([metrics, monitors, compare, population],
                           None if population else ("ci95_method",
                                                    "share_affected_ci95_method"))
    if legend:
        print(f"\n95 % intervals over the {_users(plan.users)} (the independent units):",
              file=out)
        for line in legend:
            print(line, file=out)
    print(file=out)


def _shown(metrics: Mapping[str, Any], compare: Mapping[str, Any] | None,
           population: Mapping[str, Any] | None) -> list[Any]:
    """The summaries whose intervals the terminal's tables show: every metric, per subgroup
    too, and every difference."""
    shown = list(metrics.values())
    groups = (population or {}).get("subgroups") or {}
    for g in groups.values():
        shown += list((g.get("metrics") or {}).values())
    if compare is not None:
        shown += list((compare.get("difference") or {}).values())
        for g in groups.values():
            shown += list((g.get("difference") or {}).values())
    return shown


def _print_population(out: IO[str], metrics: Mapping[str, Any],
                      population: Mapping[str, Any]) -> None:
    """The users as a population: subgroups, metrics per subgroup, how users' own values
    spread, and the parameters drawn for them."""
    if population.get("subgroups"):
        test = population.get("shares_test")
        print("\nusers by subgroup" + (f" (shares asked for vs drawn: chi-square "
                                       f"p = {test['p_value']:.3g})" if test else "") + ":",
              file=out)
        for line in table(SUBGROUP_HEADERS, subgroup_rows(population)):
            print(line, file=out)
        print("\nmetrics by subgroup (estimate [95 % CI]):", file=out)
        for line in table(*subgroup_metric_rows(metrics, population)):
            print(line, file=out)
    print("\nhow users differ (each user's own value, over users):", file=out)
    rows = distribution_rows(metrics, informative=True)
    for name, g in (population.get("subgroups") or {}).items():
        rows += distribution_rows(g.get("metrics") or {}, name, informative=True)
    for line in table(DISTRIBUTION_HEADERS, rows):
        print(line, file=out)
    print("\nparameters drawn per user:", file=out)
    for line in table(PARAMETER_HEADERS, parameter_rows(population)):
        print(line, file=out)
