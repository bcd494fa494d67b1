"""Per-metric summaries of a stored evaluation (the ``metrics`` of ``opspec evaluate --json``).

- count: ``total`` over all users, and per user ``mean``, ``sd``, ``ci95``, ``median``,
  ``p95``, ``p90``, ``p99`` of the users' totals (and ``per_day``, the mean per user-day),
  ``users_with_any`` (users with at least one) with ``share_with_any`` and its exact
  (Clopper-Pearson) ``share_with_any_ci95``;
- duration: pooled ``n``, ``mean`` (with ``ci95``), ``sd``, ``median``, ``p95`` of all
  observations, and ``per_user``: ``users``, ``mean``, ``sd``, ``ci95``, ``median``, ``p90``,
  ``p95``, ``p99`` of the users' own means (users without observations left out);
- ratio: ``value`` = Σ numerator / Σ denominator over users with ``ci95`` by what the spec
  declares of it (:func:`opspec.statistics.ratios.ratio_interval`: for a ratio declared a
  proportion, ``Proportion="true"``, such as missed / due doses, Wilson's score interval on
  the effective number of trials, and an error if a user's numerator exceeds its denominator;
  otherwise the cluster-robust t interval, widened to the exact Poisson one for a ratio of
  counts with few events), ``proportion`` (the declaration), and ``per_user``
  (the same fields over the users' own ratios, plus ``users_with_any``, ``share_with_any``
  and its exact interval: users whose numerator is not 0; and, for a declared proportion,
  ``between_user_sd``: the sd of the users' true rates with the binomial noise of each
  user's own rate taken out, about 0 when users differ only by chance).
``summarise_design(..., subgroup=NAME)`` summarises the users of one subgroup of a population
(the ``person`` table of the store; who those users were: :mod:`.population_summary`).
:func:`compare_designs` gives B − A per metric, paired by user; the user's actions per
activity are summarised by :func:`summarise_activities`, the monitors the spec declares
(``opspec:Monitor``) by :func:`summarise_monitors`.
Every interval carries the id of its method (``ci95_method``, ``share_with_any_ci95_method``…;
:mod:`opspec.statistics.methods`), and every ``ci95`` of a metric, of ``per_user`` and of a
difference its ``ci95_no_spread``: None, or what an interval of no width from users who all
gave the same value shows (:func:`opspec.statistics.no_spread.no_spread`). Quantiles of pooled
observations are computed in the database, so memory does not grow with the number of users.
Each user's values are read as :mod:`.values_per_user` holds or spills them.
"""

from __future__ import annotations

import math
import statistics as pystats
from collections.abc import Sequence
from typing import Any

from opspec.evaluation.store import ResultStore
from opspec.evaluation.values_per_user import (
    held_in_memory,
    per_user_values,
    user_pairs_by_metric,
)
from opspec.statistics import (
    count_estimate,
    hazard_estimate,
    paired_difference,
    rate_interval,
    ratio_estimate,
)
from opspec.statistics.clustered import ValuesAsPairs
from opspec.statistics.no_spread import no_spread
from opspec.statistics.percentiles import interpolation_point, linear
from opspec.statistics.ratios import ratio_interval

__all__ = ["compare_designs", "metric_definitions", "subgroup_users", "summarise_activities",
           "summarise_design", "summarise_monitors"]

#: Percentiles of per-user values reported beside the median (p50).
PERCENTILES = (("p90", 0.90), ("p95", 0.95), ("p99", 0.99))


def metric_definitions(store: ResultStore, design: str = "A") -> list[dict[str, Any]]:
    """The metrics ``design`` declares (name, kind, numerator, denominator, unit), as stored
    with the run: ``metrics`` for design A, ``metrics_B`` for B (falling back to A's in stores
    written before B's were kept)."""
    if design != "A":
        own = store.get(f"metrics_{design}")
        if own is not None:
            return list(own)
    return list(store.get("metrics") or [])


def _percentile(ordered: Sequence[float], q: float) -> float | None:
    return linear(ordered, q) if ordered else None


def subgroup_users(store: ResultStore, design: str, subgroup: str | None
                   ) -> set[int] | None:
    """The users of ``subgroup`` in ``design`` (None: every user, no filter)."""
    if subgroup is None:
        return None
    return {int(u) for (u,) in store.query(
        "SELECT user FROM person WHERE design = ? AND subgroup = ?", (design, subgroup))}


def _in_subgroup(design: str, subgroup: str | None) -> tuple[str, tuple[Any, ...]]:
    """An SQL condition on ``user`` (and its parameters) for one subgroup's users."""
    if subgroup is None:
        return "", ()
    return (" AND user IN (SELECT user FROM person WHERE design = ? AND subgroup = ?)",
            (design, subgroup))


def _pooled_quantile(store: ResultStore, design: str, metric: str, n: int, q: float,
                     subgroup: str | None = None) -> float | None:
    if n == 0:
        return None
    lo, frac = interpolation_point(n, q)
    where, params = _in_subgroup(design, subgroup)
    rows = store.query(f"SELECT value FROM sample WHERE design = ? AND metric = ?{where} "
                       "ORDER BY value LIMIT 2 OFFSET ?", (design, metric, *params, lo))
    values = [float(r[0]) for r in rows]
    if len(values) == 1 or frac == 0:
        return values[0]
    return values[0] + (values[1] - values[0]) * frac


def _sd(values: Sequence[float]) -> float | None:
    return pystats.stdev(values) if len(values) > 1 else None


def _per_user(ordered: Sequence[float], level: float) -> dict[str, Any]:
    """The distribution over users of each user's own value (their mean duration, their
    ratio; ``ordered``: ascending): how much users differ, beside the pooled estimate."""
    # each value as the pair (v, 1) made as it is read, not a tuple per user held
    estimate = ratio_estimate(ValuesAsPairs(ordered), level)
    return {"users": len(ordered), "mean": estimate.value, "sd": _sd(ordered),
            "ci95": estimate.ci, "ci95_method": estimate.method,
            "ci95_no_spread": no_spread(estimate.ci, len(ordered), level),
            "median": _percentile(ordered, 0.5),
            **{name: _percentile(ordered, q) for name, q in PERCENTILES}}


def _with_any(values: Sequence[float], level: float) -> dict[str, Any]:
    """Users whose value is not 0, their share and its exact (Clopper-Pearson) interval:
    the users who had at least one missed dose, say."""
    users = len(values)
    hit = sum(1 for v in values if v != 0)
    if users == 0:
        return {"users_with_any": 0, "share_with_any": None, "share_with_any_ci95": None,
                "share_with_any_ci95_method": None}
    _, low, high = rate_interval(hit, users, level, method="clopper-pearson")
    return {"users_with_any": hit, "share_with_any": hit / users,
            "share_with_any_ci95": [low, high],
            "share_with_any_ci95_method": "clopper-pearson"}


def _between_user_sd(pairs: Sequence[tuple[float, float]]) -> float | None:
    """For a declared proportion (whose every ``y <= n``, checked before): the sd of the
    users' true rates, by the method of moments — the variance of the users' own rates less
    the mean binomial variance of a rate measured on ``n`` trials (estimated without bias by
    ``p(1-p)/(n-1)``). About 0 when every user has the same rate and they differ only by
    chance; users with fewer than 2 trials are left out. Two passes over ``pairs``, nothing
    held per user."""
    measured = sum(1 for _, n in pairs if n >= 2)
    if measured < 2:
        return None
    observed = pystats.variance(y / n for y, n in pairs if n >= 2)
    noise = math.fsum((y / n) * (1 - y / n) / (n - 1) for y, n in pairs if n >= 2) / measured
    return math.sqrt(max(observed - noise, 0.0))


def summarise_design(store: ResultStore, design: str, days: float, level: float = 0.95, *,
                     subgroup: str | None = None) -> dict[str, dict[str, Any]]:
    """Every declared metric of ``design`` summarised (see the module docstring), over the
    users of ``subgroup`` only when it is given. The users' values are read from disk at
    each pass (:func:`.values_per_user.per_user_values`): the memory does not grow with the
    number of users."""
    out: dict[str, dict[str, Any]] = {}
    users_of = subgroup_users(store, design, subgroup)
    where, where_params = _in_subgroup(design, subgroup)
    definitions = metric_definitions(store, design)
    values = per_user_values(store, design, definitions, users_of)
    counts = {d["name"] for d in definitions if d["kind"] == "count"}
    pooled: list[tuple[str, int, float | None]] = []     # durations: (name, n, mean)
    for definition in definitions:
        name, kind = definition["name"], definition["kind"]
        pairs = values.pairs(name)
        estimate = ratio_estimate(pairs, level)
        users = len(pairs)
        if kind == "count":
            totals = values.sorted(name, "y")
            counted = count_estimate(totals, level)
            out[name] = {
                "kind": "count", "total": int(sum(totals)), "users": users,
                "mean": counted.value, "sd": _sd(totals),
                "ci95": counted.ci, "ci95_method": counted.method,
                "ci95_no_spread": no_spread(counted.ci, users, level),
                "median": _percentile(totals, 0.5), "p95": _percentile(totals, 0.95),
                "per_day": (estimate.value / days) if estimate.value is not None else None,
                "p90": _percentile(totals, 0.90), "p99": _percentile(totals, 0.99),
                **_with_any(totals, level),
            }
        elif kind == "duration":
            n = int(sum(n for _, n in pairs))
            # sd, median and p95 read the observations themselves: after every other
            # number (below), so that they wait last for the sample index being built
            # beside the summaries (ResultStore.index)
            pooled.append((name, n, estimate.value))
            out[name] = {
                "kind": "duration", "unit": definition.get("unit") or "s", "n": n,
                "users": users, "mean": estimate.value, "ci95": estimate.ci,
                "ci95_method": estimate.method, "sd": None,
                "ci95_no_spread": no_spread(estimate.ci, estimate.users, level),
                "median": None, "p95": None,
                "per_user": _per_user(values.sorted(name, "v"), level),
            }
        else:
            # the declaration, never the numbers of this run, says whether it is a proportion
            # (a store written before it was kept: every ratio is a ratio)
            proportion = bool(definition.get("proportion"))
            numerator, denominator = definition.get("numerator"), definition.get("denominator")
            interval = ratio_interval(pairs, proportion=proportion,
                                      of_counts=numerator in counts and denominator in counts,
                                      name=name, numerator=str(numerator),
                                      denominator=str(denominator), level=level)
            out[name] = {
                "kind": "ratio", "value": estimate.value, "users": users,
                "numerator_total": sum(y for y, _ in pairs),
                "denominator_total": sum(k for _, k in pairs),
                "ci95": interval.ci, "ci95_method": interval.method,
                "ci95_no_spread": no_spread(interval.ci, interval.users, level),
                "proportion": proportion,
                "numerator": numerator, "denominator": denominator,
                "per_user": {**_per_user(values.sorted(name, "v"), level),
                             **_with_any(values.where_denominator(name), level),
                             "between_user_sd": (_between_user_sd(pairs) if proportion
                                                 else None)},
            }
    for name, n, mean in pooled:
        sq = store.query("SELECT SUM(value * value) FROM sample WHERE design = ? AND "
                         f"metric = ?{where}", (design, name, *where_params))
        if n > 1 and mean is not None and sq and sq[0][0] is not None:
            var = (float(sq[0][0]) - n * mean ** 2) / (n - 1)
            out[name]["sd"] = math.sqrt(max(var, 0.0))
        out[name]["median"] = _pooled_quantile(store, design, name, n, 0.5, subgroup)
        out[name]["p95"] = _pooled_quantile(store, design, name, n, 0.95, subgroup)
    return out


def compare_designs(store: ResultStore, a: str = "A", b: str = "B", level: float = 0.95, *,
                    subgroup: str | None = None) -> dict[str, dict[str, Any]]:
    """Per metric both designs declare alike (same name, kind, numerator and denominator):
    B − A on the users both designs finished, paired by user (the users of ``subgroup``
    only, when it is given)."""
    out: dict[str, dict[str, Any]] = {}
    only = subgroup_users(store, a, subgroup)
    theirs = {d["name"]: d for d in metric_definitions(store, b)}
    alike = [d for d in metric_definitions(store, a)
             if (other := theirs.get(d["name"])) is not None
             and all(other.get(k) == d.get(k) for k in ("kind", "numerator", "denominator"))]
    of_a = user_pairs_by_metric(store, a, alike, only)
    of_b = user_pairs_by_metric(store, b, alike, only)
    for definition in alike:
        pairs_a = dict(of_a[definition["name"]])
        pairs_b = dict(of_b[definition["name"]])
        users = sorted(set(pairs_a) & set(pairs_b))
        diff = paired_difference([pairs_a[u] for u in users], [pairs_b[u] for u in users],
                                 level)
        ea = ratio_estimate([pairs_a[u] for u in users], level)
        eb = ratio_estimate([pairs_b[u] for u in users], level)
        significant = (diff.low is not None and diff.high is not None
                       and (diff.low > 0 or diff.high < 0))
        out[definition["name"]] = {
            "kind": definition["kind"], "unit": definition.get("unit") or (
                "s" if definition["kind"] == "duration" else None),
            "a": ea.value, "b": eb.value,
            "difference": diff.value, "ci95": diff.ci, "ci95_method": diff.method,
            "ci95_no_spread": no_spread(diff.ci, len(users), level),
            "users": len(users),
            "significant": significant,
            # a ratio's declaration, as its summaries carry it: the tables show the
            # difference of a proportion in percentage points (tables.in_percent)
            **({"proportion": bool(definition.get("proportion"))}
               if definition["kind"] == "ratio" else {}),
        }
    return out


def summarise_activities(store: ResultStore, design: str) -> list[dict[str, Any]]:
    """Per manual activity of the user's lane (in the order first stored): ``offered``, the
    ``omission`` and ``error`` rates per offer, and their intervals over users (each user's
    omissions of their offers: a proportion pooled over users, as a metric's missed rate,
    method ``wilson-neff``). Activities never offered are left out. The users' counts are
    held in lists for at most :data:`.values_per_user.HELD_USERS` users, else read from disk
    at each pass (:func:`opspec.evaluation.spilled.spill_activities`)."""
    from opspec.evaluation.spilled import held_activities, spill_activities
    from opspec.statistics import proportion_interval

    most = store.query("SELECT MAX(c) FROM (SELECT COUNT(*) AS c FROM activity WHERE "
                       "design = ? GROUP BY activity)", (design,))[0][0]
    counts = (held_activities(store, design) if held_in_memory(int(most or 0))
              else spill_activities(store, design))
    out = []
    for activity, offered, omissions, wrongs in counts:
        out.append({"activity": activity, "offered": offered,
                    "omission": int(sum(y for y, _ in omissions)) / offered,
                    "error": int(sum(y for y, _ in wrongs)) / offered,
                    "omission_ci95": proportion_interval(omissions),
                    "error_ci95": proportion_interval(wrongs),
                    "ci95_method": "wilson-neff"})
    return out


def _users_affected_ci(affected: int, users: int, level: float) -> list[float]:
    _, low, high = rate_interval(affected, users, level, method="clopper-pearson")
    return [low, high]


def summarise_monitors(store: ResultStore, design: str, days: float, level: float = 0.95
                       ) -> dict[str, dict[str, Any]]:
    """Per monitor ``design`` declares, over its finished users: ``violations`` (total),
    ``users`` and ``users_affected`` (with at least one violation) with the share affected and
    its exact (Clopper-Pearson) interval, and the hazard ``per_user_day`` = violations /
    (users × days) with ``ci95``. The hazard's interval is the envelope of the exact Poisson
    (Garwood) interval, which is right when violations are rare and independent and gives a
    real upper bound when there are none, and the cluster-robust interval over users, which
    is right when violations cluster in some users (a late reporter violates again and
    again); the wider of the two is reported. ``first`` is the earliest user's first
    violation (user, simulated time, message), for finding it in a trace."""
    rows = store.query(
        "SELECT m.monitor, m.user, m.violations, m.first_time, m.first_message FROM monitor m "
        "JOIN replication r ON r.design = m.design AND r.user = m.user "
        "WHERE m.design = ? AND r.status = 'done' ORDER BY m.rowid", (design,))
    per_monitor: dict[str, list[tuple[int, int, float | None, str | None]]] = {}
    for monitor, user, count, first_time, first_message in rows:
        per_monitor.setdefault(str(monitor), []).append(
            (int(user), int(count), first_time, first_message))
    out: dict[str, dict[str, Any]] = {}
    for monitor, users_rows in per_monitor.items():
        users = len(users_rows)
        total = sum(c for _, c, _, _ in users_rows)
        affected = sum(1 for _, c, _, _ in users_rows if c > 0)
        hazard = hazard_estimate([c for _, c, _, _ in users_rows], days, level)
        first = min(((u, t, m) for u, c, t, m in users_rows if c > 0), default=None,
                    key=lambda x: x[0])
        out[monitor] = {
            "violations": total, "users": users, "users_affected": affected,
            "share_affected": affected / users if users else None,
            "share_affected_ci95": _users_affected_ci(affected, users, level) if users else None,
            "share_affected_ci95_method": "clopper-pearson" if users else None,
            "per_user_day": hazard.value, "ci95": hazard.ci, "ci95_method": hazard.method,
            "first": None if first is None else {"user": first[0], "time": first[1],
                                                 "message": first[2]},
        }
    return out

