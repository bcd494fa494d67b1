"""Who the simulated users were, when the user model is a population (the ``population`` of
``opspec evaluate --json``): per subgroup the users (realised share with its exact interval,
the share the model asks for, and a chi-square test of the shares), the drawn parameters,
every metric (as :func:`.design_summary.summarise_design` over the subgroup's users), and
with two designs the paired differences.
"""

from __future__ import annotations

import math
import statistics as pystats
from collections.abc import Sequence
from typing import Any

from opspec.evaluation.design_summary import (
    _percentile,
    _sd,
    compare_designs,
    summarise_design,
)
from opspec.evaluation.store import ResultStore
from opspec.statistics import rate_interval

__all__ = ["has_population", "summarise_population"]


def has_population(store: ResultStore) -> bool:
    """Whether the store holds who each user is (a run with a population user model)."""
    try:
        rows = store.query("SELECT 1 FROM person LIMIT 1")
    except Exception:  # noqa: BLE001 - a store written before populations existed
        return False
    return bool(rows)


def _people(store: ResultStore, design: str
            ) -> tuple[dict[int, str | None], dict[int, dict[str, float]], list[str]]:
    """Finished users of ``design``: their subgroup, their drawn parameters, and the
    parameter names in the order they were drawn."""
    groups = {int(u): g for u, g in store.query(
        "SELECT p.user, p.subgroup FROM person p JOIN replication r ON r.design = p.design "
        "AND r.user = p.user WHERE p.design = ? AND r.status = 'done' ORDER BY p.user",
        (design,))}
    values: dict[int, dict[str, float]] = {}
    names: dict[str, None] = {}
    for user, name, value in store.query(
            "SELECT user, parameter, value FROM person_parameter WHERE design = ? "
            "ORDER BY rowid", (design,)):
        if int(user) in groups:
            values.setdefault(int(user), {})[str(name)] = float(value)
            names.setdefault(str(name))
    return groups, values, list(names)


def _parameter_stats(values: Sequence[float]) -> dict[str, Any]:
    ordered = sorted(values)
    return {"users": len(ordered), "mean": pystats.fmean(ordered) if ordered else None,
            "sd": _sd(ordered), "min": ordered[0] if ordered else None,
            "p5": _percentile(ordered, 0.05), "median": _percentile(ordered, 0.5),
            "p95": _percentile(ordered, 0.95), "max": ordered[-1] if ordered else None}


def _declared(store: ResultStore) -> Any:
    """The population of the run's user model as the file says it now (for the shares it
    asks for and the distributions it declares); None when it cannot be loaded."""
    plan = store.get("plan") or {}
    ref = plan.get("user_model")
    if not ref:
        return None
    try:
        from opspec.usermodels.loader import load_user_model

        return load_user_model(str(ref)).population
    except Exception:  # noqa: BLE001 - the realised numbers stand without the declared ones
        return None


def summarise_population(store: ResultStore, days: float, level: float = 0.95, *,
                         designs: Sequence[str] = ("A",)) -> dict[str, Any] | None:
    """Who the simulated users were, when the user model is a population (None otherwise).

    ``parameters``: per drawn parameter, over all users, ``mean``, ``sd``, ``min``, ``p5``,
    ``median``, ``p95``, ``max``; ``subgroups`` (when the model declares them): per subgroup
    ``users``, ``share`` with its exact ``share_ci95``, ``expected_share`` (what the model
    asks for), its ``parameters``, ``metrics`` (as :func:`summarise_design`) of the first
    design, ``metrics_<label>`` of the others, and ``difference`` (paired, second − first);
    ``shares_test``: Pearson's chi-square test of the realised subgroup counts against the
    shares asked for (a small ``p_value`` says the draw does not realise them)."""
    if not has_population(store):
        return None
    first = designs[0]
    groups, values, names = _people(store, first)
    if not groups:
        return None
    declared = _declared(store)
    expected = ({g.name: g.share for g in declared.subgroups} if declared is not None
                else {})
    out: dict[str, Any] = {
        "users": len(groups),
        "parameters": {n: _parameter_stats([v[n] for v in values.values() if n in v])
                       for n in names},
        "subgroups": {},
    }
    order = [g for g in expected if g is not None] if expected else []
    order += sorted({g for g in groups.values() if g is not None and g not in order})
    if not order:
        return out
    total = len(groups)
    counts = {g: sum(1 for x in groups.values() if x == g) for g in order}
    for name in order:
        members = [u for u, g in groups.items() if g == name]
        _, low, high = rate_interval(len(members), total, level, method="clopper-pearson")
        entry: dict[str, Any] = {
            "users": len(members), "share": len(members) / total, "share_ci95": [low, high],
            "share_ci95_method": "clopper-pearson",
            "expected_share": expected.get(name),
            "parameters": {n: _parameter_stats([values[u][n] for u in members
                                                if n in values.get(u, {})]) for n in names},
            "metrics": summarise_design(store, first, days, level, subgroup=name),
        }
        for other in designs[1:]:
            entry[f"metrics_{other}"] = summarise_design(store, other, days, level,
                                                         subgroup=name)
        if len(designs) > 1:
            entry["difference"] = compare_designs(store, first, designs[1], level,
                                                  subgroup=name)
        out["subgroups"][name] = entry
    if expected and len(order) > 1 and all(expected.get(g) for g in order):
        from scipy import stats

        asked = math.fsum(expected[g] for g in order)   # 1, within the loader's tolerance
        test = stats.chisquare([counts[g] for g in order],
                               [expected[g] / asked * total for g in order])
        out["shares_test"] = {"chi2": float(test.statistic), "df": len(order) - 1,
                              "p_value": float(test.pvalue)}
    return out
