"""Every interval of an evaluation is what its stated method computes.

`opspec evaluate --json` names the method of each interval (``ci95_method`` and friends) and
defines it under ``interval_methods``. This test runs a small evaluation (the dispenser with a
monitor, compared with a four-alarm variant on the same users), reads the raw per-user
results back from ``results.sqlite`` with sqlite3, and recomputes every interval of the JSON by
the stated method with statsmodels and scipy — independent implementations, not opspec's:

* ``t``: the cluster-robust (delta-method) interval of Σy/Σn over users is the weighted least
  squares mean of y/n with weights n and the HC1 sandwich variance (MacKinnon & White 1985:
  "HC1 ... multiplies HC0 by n/(n−k)"), on U−1 degrees of freedom; for a count it is the t
  interval of the mean of the users' totals (statsmodels ``DescrStatsW.tconfint_mean``);
* ``t+garwood``: the union with the exact Poisson interval [χ²(α/2; 2k)/2, χ²(1−α/2; 2k+2)/2]
  (Garwood 1936), divided by the users;
* ``t+garwood-rate``: the union with the exact Poisson interval of the numerator's events over
  the denominator's trials, for a ratio of counts with fewer than 10 events;
* ``wilson-neff``: statsmodels' Wilson interval (``proportion_confint(method="wilson")``) on
  the effective number of trials, with the stated design effect, for a ratio the spec
  declares a proportion;
* ``clopper-pearson``: statsmodels' ``proportion_confint(method="beta")``;
* ``garwood+t``, ``paired-t``, ``paired-t+garwood``, ``paired-t-few``: as defined.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import sqlite3
from pathlib import Path
from typing import Any

import pytest
from evaluate_without_report import without_report
from scipy import stats

from opspec.cli import main
from opspec.statistics.methods import METHODS

sm_proportion = pytest.importorskip("statsmodels.stats.proportion")
sm_weightstats = pytest.importorskip("statsmodels.stats.weightstats")
sm_api = pytest.importorskip("statsmodels.api")

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
ANCHOR = '  <ExtendedAttributes>\n    <ExtendedAttribute Name="opspec:Metrics">'
ALPHA = 0.05
Pairs = list[tuple[float, float]]


@pytest.fixture(scope="module")
def evaluation(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, Any], Path]:
    folder = tmp_path_factory.mktemp("methods")
    text = SPEC.read_text(encoding="utf-8")
    assert ANCHOR in text and text.count("<Expression>alarms &lt; 3</Expression>") == 1
    monitored = text.replace(ANCHOR, ANCHOR.split("\n")[0] + "\n"
                             '    <ExtendedAttribute Name="opspec:Monitor" '
                             'Value="min_gap dispense 4h"/>\n' + ANCHOR.split("\n")[1])
    spec_a, spec_b = folder / "a.xpdl", folder / "b.xpdl"
    spec_a.write_text(monitored, encoding="utf-8")
    spec_b.write_text(monitored.replace("<Expression>alarms &lt; 3</Expression>",
                                        "<Expression>alarms &lt; 4</Expression>"),
                      encoding="utf-8")
    out = io.StringIO()
    # the numbers are the point: no report (tests/evaluate_without_report.py)
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()), \
            without_report():
        status = main(["evaluate", str(spec_a), "--compare", str(spec_b), "--user-model",
                       str(USERS), "--users", "12", "--days", "3", "--seed", "2",
                       "--workers", "1", "--out", str(folder / "out"), "--json"])
    assert status == 0
    return json.loads(out.getvalue()), folder / "out" / "results.sqlite"


# ------------------------------------------------------------------ the raw data, via sqlite3
def _read(db: Path) -> tuple[dict[str, list[dict[str, Any]]], dict[str, dict[int, Any]],
                             dict[str, dict[int, int]], float]:
    with sqlite3.connect(db) as con:
        run = {k: json.loads(v) for k, v in con.execute("SELECT key, value FROM run")}
        users = {d: {int(u): json.loads(m) for u, m in con.execute(
            "SELECT user, metrics FROM replication WHERE design = ? AND status = 'done' "
            "ORDER BY user", (d,))} for d in ("A", "B")}
        monitors = {d: {int(u): int(v) for u, v in con.execute(
            "SELECT user, violations FROM monitor WHERE design = ? ORDER BY user", (d,))}
            for d in ("A", "B")}
    definitions = {"A": run["metrics"], "B": run.get("metrics_B") or run["metrics"]}
    return definitions, users, monitors, float(run["days"])


def _scalar(metric: dict[str, Any] | None) -> tuple[float, float]:
    if not metric:
        return 0.0, 0.0
    if metric["kind"] == "count":
        return float(metric["total"]), 1.0
    n = float(metric.get("n") or 0)
    return (float(metric["mean"]) * n if n else 0.0), n


def _pairs(definition: dict[str, Any], users: dict[int, Any]) -> Pairs:
    if definition["kind"] == "ratio":
        return [(_scalar(m.get(definition["numerator"]))[0],
                 _scalar(m.get(definition["denominator"]))[0]) for m in users.values()]
    return [_scalar(m.get(definition["name"])) for m in users.values()]


# ------------------------------------------------------------------ the stated methods
def _t(pairs: Pairs) -> tuple[float, float, float]:
    """Σy/Σn with the cluster-robust t interval: WLS of y/n on a constant, weights n, HC1."""
    y = [a / n if n else 0.0 for a, n in pairs]
    w = [n for _, n in pairs]
    fit = sm_api.WLS(y, [[1.0]] * len(y), weights=w).fit(cov_type="HC1", use_t=True)
    low, high = fit.conf_int(alpha=ALPHA)[0]
    assert fit.df_resid == len(pairs) - 1
    return float(fit.params[0]), max(0.0, float(low)), float(high)


def _t_mean(values: list[float]) -> tuple[float, float]:
    if len(set(values)) == 1:
        return values[0], values[0]
    low, high = sm_weightstats.DescrStatsW(values).tconfint_mean(alpha=ALPHA)
    return max(0.0, float(low)), float(high)


def _garwood(k: int, exposure: float, alpha: float = ALPHA) -> tuple[float, float]:
    low = 0.0 if k == 0 else stats.chi2.ppf(alpha / 2, 2 * k) / 2
    return low / exposure, stats.chi2.ppf(1 - alpha / 2, 2 * k + 2) / 2 / exposure


def _union(a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float]:
    return min(a[0], b[0]), max(a[1], b[1])


def _wilson_neff(pairs: Pairs) -> tuple[float, float]:
    trials = sum(n for _, n in pairs)
    events = sum(y for y, _ in pairs)
    p = events / trials
    n_eff = trials
    if 0 < p < 1:
        v_users = _t_se(pairs) ** 2
        v_bin = p * (1 - p) / trials
        factor = (stats.t.ppf(0.975, len(pairs) - 1) / stats.norm.ppf(0.975)) ** 2
        n_eff = p * (1 - p) / (v_bin + factor * max(0.0, v_users - v_bin))
    low, high = sm_proportion.proportion_confint(p * n_eff, n_eff, alpha=ALPHA,
                                                 method="wilson")
    low, high = (0.0 if p == 0 else float(low)), (1.0 if p == 1 else float(high))
    if 1 <= events <= 2:
        low = min(low, stats.chi2.ppf(ALPHA, 2 * events) / 2 / trials)
    if 1 <= trials - events <= 2:
        high = max(high, 1 - stats.chi2.ppf(ALPHA, 2 * (trials - events)) / 2 / trials)
    return low, high


def _t_se(pairs: Pairs) -> float:
    y = [a / n if n else 0.0 for a, n in pairs]
    fit = sm_api.WLS(y, [[1.0]] * len(y), weights=[n for _, n in pairs]).fit(cov_type="HC1")
    return float(fit.bse[0])


def _clopper_pearson(k: int, n: int) -> tuple[float, float]:
    low, high = sm_proportion.proportion_confint(k, n, alpha=ALPHA, method="beta")
    return (0.0 if k == 0 else float(low)), (1.0 if k == n else float(high))


def _paired(a: Pairs, b: Pairs) -> dict[str, Any]:
    """Every paired method's interval, and which one the definitions say applies."""
    ra, rb = sum(y for y, _ in a) / sum(n for _, n in a), sum(y for y, _ in b) / sum(
        n for _, n in b)
    users = len(a)
    na, nb = sum(n for _, n in a) / users, sum(n for _, n in b) / users
    d = [(yb - rb * mb) / nb - (ya - ra * ma) / na for (ya, ma), (yb, mb) in zip(a, b)]
    sd = stats.tstd(d) if len(set(d)) > 1 else 0.0
    diff = rb - ra
    counts = all(x == int(x) for p in a + b for x in p) and all(
        ma == mb for (_, ma), (_, mb) in zip(a, b))
    if counts:
        up = sum(max(int(yb - ya), 0) for (ya, _), (yb, _) in zip(a, b))
        down = sum(max(int(ya - yb), 0) for (ya, _), (yb, _) in zip(a, b))
        half = stats.t.ppf(0.975, users - 1) * sd / math.sqrt(users)
        t_ci = (diff - half, diff + half)
        if up + down >= 10:
            return {"method": "paired-t", "ci": t_ci}
        total = sum(n for _, n in a)
        up_ci, down_ci = _garwood(up, total), _garwood(down, total)
        return {"method": "paired-t+garwood",
                "ci": _union(t_ci, (up_ci[0] - down_ci[1], up_ci[1] - down_ci[0]))}
    differing = sum(1 for pa, pb in zip(a, b) if pa != pb)
    if differing < 2:
        return {"method": None, "ci": None}
    df = users - 1 if differing >= 10 else min(users - 1, differing - 1)
    half = stats.t.ppf(0.975, df) * sd / math.sqrt(users)
    return {"method": "paired-t" if differing >= 10 else "paired-t-few",
            "ci": (diff - half, diff + half)}


# ------------------------------------------------------------------ the comparison
def _expect(checked: list[str], where: str, method: str | None, ci: Any,
            stated: str | None, reported: Any) -> None:
    assert stated == method, f"{where}: states {stated}, the definitions give {method}"
    if method is None:
        assert reported in (None, [None, None]), where
    else:
        assert reported == pytest.approx(list(ci), rel=1e-9, abs=1e-12), where
    checked.append(where)


def _design(checked: list[str], label: str, summary: dict[str, Any],
            definitions: list[dict[str, Any]], users: dict[int, Any]) -> None:
    for definition in definitions:
        name, kind = definition["name"], definition["kind"]
        s, pairs = summary[name], _pairs(definition, users)
        where = f"{label}.{name}"
        if kind == "count":
            totals = [y for y, _ in pairs]
            ci = _t_mean(totals)
            method = "t"
            if sum(totals) < 10:
                ci, method = _union(ci, _garwood(int(sum(totals)), len(totals))), "t+garwood"
            _expect(checked, where, method, ci, s["ci95_method"], s["ci95"])
            own = totals
        elif kind == "ratio" and definition["proportion"]:
            # the spec's declaration (Proportion="true"), not the numbers, makes it one
            _expect(checked, where, "wilson-neff", _wilson_neff(pairs), s["ci95_method"],
                    s["ci95"])
            own = [y / n for y, n in pairs if n > 0]
        else:
            _, low, high = _t(pairs)
            method, ci = "t", (low, high)
            events = sum(y for y, _ in pairs)
            if kind == "ratio" and events < 10 and {definition["numerator"], definition[
                    "denominator"]} <= {d["name"] for d in definitions if d["kind"] == "count"}:
                method = "t+garwood-rate"
                ci = _union(ci, _garwood(int(events), sum(n for _, n in pairs)))
            _expect(checked, where, method, ci, s["ci95_method"], s["ci95"])
            own = [y / n for y, n in pairs if n > 0]
        per_user = s if kind == "count" else s["per_user"]
        if kind != "count":
            _expect(checked, f"{where}.per_user", "t", _t_mean(own),
                    per_user["ci95_method"], per_user["ci95"])
        if "share_with_any_ci95" in per_user:
            hit = sum(1 for v in ([y for y, n in pairs if n > 0] if kind == "ratio" else own)
                      if v != 0)
            counted = len([1 for _, n in pairs if n > 0]) if kind == "ratio" else len(own)
            _expect(checked, f"{where}.share_with_any", "clopper-pearson",
                    _clopper_pearson(hit, counted), per_user["share_with_any_ci95_method"],
                    per_user["share_with_any_ci95"])


def _monitors(checked: list[str], label: str, summary: dict[str, Any],
              violations: dict[int, int], days: float) -> None:
    for name, m in summary.items():
        counts = list(violations.values())
        users = len(counts)
        _, low, high = _t([(float(c), days) for c in counts])
        ci = _union(_garwood(sum(counts), users * days), (low, high))
        _expect(checked, f"{label}.monitor {name}", "garwood+t", ci, m["ci95_method"],
                m["ci95"])
        _expect(checked, f"{label}.monitor {name}.share_affected", "clopper-pearson",
                _clopper_pearson(sum(1 for c in counts if c), users),
                m["share_affected_ci95_method"], m["share_affected_ci95"])


def _stated(doc: Any) -> int:
    """How many intervals the document states a method for."""
    if isinstance(doc, dict):
        return sum(1 if k.endswith("_method") and v is not None else _stated(v)
                   for k, v in doc.items() if k != "interval_methods")
    return sum(_stated(v) for v in doc) if isinstance(doc, list) else 0


def test_every_interval_is_what_its_stated_method_computes(evaluation):
    doc, db = evaluation
    definitions, users, violations, days = _read(db)
    checked: list[str] = []
    _design(checked, "A", doc["metrics"], definitions["A"], users["A"])
    _design(checked, "B", doc["compare"]["metrics"], definitions["B"], users["B"])
    _monitors(checked, "A", doc["monitors"], violations["A"], days)
    _monitors(checked, "B", doc["compare"]["monitors"], violations["B"], days)
    for definition in definitions["A"]:
        name = definition["name"]
        d = doc["compare"]["difference"][name]
        paired = _paired(_pairs(definition, users["A"]), _pairs(definition, users["B"]))
        reported = d["ci95"] if d["ci95_method"] else None
        _expect(checked, f"B-A.{name}", paired["method"], paired["ci"], d["ci95_method"],
                reported)
    # every interval that states a method was recomputed (none left unchecked)
    stated = _stated({k: doc[k] for k in ("metrics", "monitors", "compare")})
    assert len(checked) >= stated
    # the evaluation exercised the methods of every metric kind
    used = {m for m in doc["interval_methods"]}
    assert {"t", "t+garwood", "wilson-neff", "clopper-pearson", "garwood+t"} <= used
    assert used & {"paired-t", "paired-t+garwood", "paired-t-few"}


def test_every_stated_method_is_defined_with_its_references(evaluation):
    doc, _ = evaluation
    for method_id, described in doc["interval_methods"].items():
        assert method_id in METHODS
        assert described["definition"] and described["references"]
    assert "Wilson (1927)" in " ".join(doc["interval_methods"]["wilson-neff"]["references"])
    assert "Garwood (1936)" in " ".join(doc["interval_methods"]["t+garwood"]["references"])
    assert "Clopper & Pearson (1934)" in " ".join(
        doc["interval_methods"]["clopper-pearson"]["references"])
