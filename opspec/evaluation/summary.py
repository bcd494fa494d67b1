"""Per-metric summaries of a stored evaluation (the ``metrics`` of ``opspec evaluate --json``).

- count: ``total`` over all users, and per user ``mean``, ``sd``, ``ci95``, ``median``,
  ``p95`` of the users' totals (and ``per_day``, the mean per user-day);
- duration: pooled ``n``, ``mean`` (with ``ci95``), ``sd``, ``median``, ``p95`` of all
  observations, and ``per_user``: ``users``, ``mean``, ``sd``, ``ci95``, ``median``, ``p95``
  of the users' own means (users without observations left out);
- ratio: ``value`` = Σ numerator / Σ denominator over users with ``ci95``, and ``per_user``
  (the same fields, over the users' own ratios).
Monitors the spec declares (``opspec:Monitor``) are summarised by :func:`summarise_monitors`.
Intervals are described in :mod:`opspec.statistics`. Quantiles of pooled
observations are computed in the database, so memory does not grow with the number of users.
"""

from __future__ import annotations

import math
import statistics as pystats
from collections.abc import Mapping, Sequence
from typing import Any

from opspec.evaluation.store import ResultStore
from opspec.statistics import paired_difference, poisson_interval, rate_interval, ratio_estimate

__all__ = ["compare_designs", "metric_definitions", "summarise_design", "summarise_monitors",
           "user_pairs"]


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
    if not ordered:
        return None
    pos = (len(ordered) - 1) * q
    lo = math.floor(pos)
    hi = min(lo + 1, len(ordered) - 1)
    return ordered[lo] + (ordered[hi] - ordered[lo]) * (pos - lo)


def _scalar_pair(metric: Mapping[str, Any] | None) -> tuple[float, float]:
    """(y, n) of one user's value of a count or duration metric."""
    if not metric:
        return 0.0, 0.0
    if metric.get("kind") == "count":
        return float(metric.get("total") or 0), 1.0
    if metric.get("kind") == "duration":
        n = float(metric.get("n") or 0)
        mean = metric.get("mean")
        return (float(mean) * n if mean is not None else 0.0), n
    value = metric.get("value")
    return (float(value), 1.0) if value is not None else (0.0, 0.0)


def user_pairs(store: ResultStore, design: str, definition: Mapping[str, Any]
               ) -> list[tuple[int, tuple[float, float]]]:
    """Per finished user of ``design``: the (y, n) pair of ``definition``'s metric."""
    name = definition["name"]
    out = []
    for user, metrics in store.user_metrics(design):
        if definition["kind"] == "ratio":
            num, _ = _scalar_pair(metrics.get(definition.get("numerator") or ""))
            den, _ = _scalar_pair(metrics.get(definition.get("denominator") or ""))
            out.append((user, (num, den)))
        else:
            out.append((user, _scalar_pair(metrics.get(name))))
    return out


def _pooled_quantile(store: ResultStore, design: str, metric: str, n: int, q: float
                     ) -> float | None:
    if n == 0:
        return None
    pos = (n - 1) * q
    lo = math.floor(pos)
    rows = store.query("SELECT value FROM sample WHERE design = ? AND metric = ? "
                       "ORDER BY value LIMIT 2 OFFSET ?", (design, metric, lo))
    values = [float(r[0]) for r in rows]
    if len(values) == 1 or pos == lo:
        return values[0]
    return values[0] + (values[1] - values[0]) * (pos - lo)


def _sd(values: Sequence[float]) -> float | None:
    return pystats.stdev(values) if len(values) > 1 else None


def _per_user(values: Sequence[float], level: float) -> dict[str, Any]:
    """The distribution over users of each user's own value (their mean duration, their
    ratio): how much users differ, beside the pooled estimate."""
    ordered = sorted(values)
    estimate = ratio_estimate([(v, 1.0) for v in ordered], level)
    return {"users": len(ordered), "mean": estimate.value, "sd": _sd(ordered),
            "ci95": estimate.ci, "median": _percentile(ordered, 0.5),
            "p95": _percentile(ordered, 0.95)}


#: Fewer events than this (or, for a proportion, fewer non-events) and the normal
#: approximation behind the cluster-robust interval is not to be trusted (the usual np >= 10
#: rule): the interval is widened to cover the exact Poisson (counts) or Wilson score
#: (proportions) interval, which never collapses to [0, 0] with no events.
RARE_EVENTS = 10


def _rare_count_ci(ci: list[float | None], total: int, users: int, level: float
                   ) -> list[float | None]:
    if users < 1 or total >= RARE_EVENTS:
        return ci
    _rate, low, high = poisson_interval(total, float(users), level)
    return [low if ci[0] is None else min(ci[0], low),
            high if ci[1] is None else max(ci[1], high)]


def _rare_proportion_ci(ci: list[float | None], pairs: Sequence[tuple[float, float]],
                        level: float) -> list[float | None]:
    """A ratio of counts that is a proportion (numerator <= denominator for every user, all
    whole numbers) with few events or few non-events: widened to its Wilson interval."""
    if not pairs or any(y > n or y < 0 or y != int(y) or n != int(n) for y, n in pairs):
        return ci
    events, trials = int(sum(y for y, _ in pairs)), int(sum(n for _, n in pairs))
    if trials <= 0 or min(events, trials - events) >= RARE_EVENTS:
        return ci
    wilson = rate_interval(events, trials, level)
    return [wilson.lo if ci[0] is None else min(ci[0], wilson.lo),
            wilson.hi if ci[1] is None else max(ci[1], wilson.hi)]


def summarise_design(store: ResultStore, design: str, days: float, level: float = 0.95
                     ) -> dict[str, dict[str, Any]]:
    """Every declared metric of ``design`` summarised (see the module docstring)."""
    out: dict[str, dict[str, Any]] = {}
    for definition in metric_definitions(store, design):
        name, kind = definition["name"], definition["kind"]
        pairs = [p for _, p in user_pairs(store, design, definition)]
        estimate = ratio_estimate(pairs, level)
        users = len(pairs)
        if kind == "count":
            totals = sorted(y for y, _ in pairs)
            out[name] = {
                "kind": "count", "total": int(sum(totals)), "users": users,
                "mean": estimate.value, "sd": _sd(totals),
                "ci95": _rare_count_ci(estimate.ci, int(sum(totals)), users, level),
                "median": _percentile(totals, 0.5), "p95": _percentile(totals, 0.95),
                "per_day": (estimate.value / days) if estimate.value is not None else None,
            }
        elif kind == "duration":
            n = int(sum(n for _, n in pairs))
            means = [y / k for y, k in pairs if k > 0]
            sq = store.query("SELECT SUM(value * value) FROM sample WHERE design = ? AND "
                             "metric = ?", (design, name))
            sd = None
            if n > 1 and estimate.value is not None and sq and sq[0][0] is not None:
                var = (float(sq[0][0]) - n * estimate.value ** 2) / (n - 1)
                sd = math.sqrt(max(var, 0.0))
            out[name] = {
                "kind": "duration", "unit": definition.get("unit") or "s", "n": n,
                "mean": estimate.value, "ci95": estimate.ci, "sd": sd,
                "median": _pooled_quantile(store, design, name, n, 0.5),
                "p95": _pooled_quantile(store, design, name, n, 0.95),
                "per_user": _per_user(means, level),
            }
        else:
            ratios = [y / k for y, k in pairs if k > 0]
            out[name] = {
                "kind": "ratio", "value": estimate.value,
                "ci95": _rare_proportion_ci(estimate.ci, pairs, level),
                "numerator": definition.get("numerator"),
                "denominator": definition.get("denominator"),
                "per_user": _per_user(ratios, level),
            }
    return out


def compare_designs(store: ResultStore, a: str = "A", b: str = "B", level: float = 0.95
                    ) -> dict[str, dict[str, Any]]:
    """Per metric both designs declare alike (same name, kind, numerator and denominator):
    B − A on the users both designs finished, paired by user."""
    out: dict[str, dict[str, Any]] = {}
    theirs = {d["name"]: d for d in metric_definitions(store, b)}
    for definition in metric_definitions(store, a):
        other = theirs.get(definition["name"])
        if other is None or any(other.get(k) != definition.get(k)
                                for k in ("kind", "numerator", "denominator")):
            continue
        pairs_a = dict(user_pairs(store, a, definition))
        pairs_b = dict(user_pairs(store, b, definition))
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
            "difference": diff.value, "ci95": diff.ci, "users": len(users),
            "significant": significant,
        }
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
        exposure = users * days
        rate, p_lo, p_hi = poisson_interval(total, exposure, level)
        robust = ratio_estimate([(float(c), days) for _, c, _, _ in users_rows], level)
        lo = p_lo if robust.low is None else min(p_lo, robust.low)
        hi = p_hi if robust.high is None else max(p_hi, robust.high)
        first = min(((u, t, m) for u, c, t, m in users_rows if c > 0), default=None,
                    key=lambda x: x[0])
        out[monitor] = {
            "violations": total, "users": users, "users_affected": affected,
            "share_affected": affected / users if users else None,
            "share_affected_ci95": _users_affected_ci(affected, users, level) if users else None,
            "per_user_day": rate, "ci95": [lo, hi],
            "first": None if first is None else {"user": first[0], "time": first[1],
                                                 "message": first[2]},
        }
    return out
