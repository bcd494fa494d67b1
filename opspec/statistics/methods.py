"""How each interval of an evaluation is computed, in words and with its references.

Every ``ci95`` of ``opspec evaluate`` carries the id of the method that produced it
(``ci95_method``); this table is what the terminal, ``--json``, the report and
docs/evaluation.md say about each id, so the four cannot tell different stories.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["METHODS", "Method", "describe", "methods_in"]


@dataclass(frozen=True, slots=True)
class Method:
    """One way of computing an interval: ``name`` fits a table cell, ``summary`` a line,
    ``definition`` is the recipe a reader can recompute it from, ``references`` where it
    comes from."""

    id: str
    name: str
    summary: str
    definition: str
    references: tuple[str, ...]

    @property
    def cited(self) -> str:
        """The references as author-year citations: ``Wilson 1927; Kish 1965``."""
        return "; ".join(re.sub(r"^(.*?) \((\d{4})\).*$", r"\1 \2", r)
                         for r in self.references)


_T = "Student (1908), Biometrika 6:1–25"
_RATIO = "Cochran (1977), Sampling Techniques, 3rd ed., §6 (ratio estimator)"
_GARWOOD = "Garwood (1936), Biometrika 28:437–442"
_WILSON = "Wilson (1927), J Am Stat Assoc 22:209–212"
_CP = "Clopper & Pearson (1934), Biometrika 26:404–413"
_ULM = "Ulm (1990), Am J Epidemiol 131:373–375 (exact Poisson interval of a rate)"

METHODS: Mapping[str, Method] = {m.id: m for m in (
    Method("t", "t",
           "Student t on U−1 df with the cluster-robust (delta-method) standard error of Σy/Σn",
           "r = Σy/Σn over the U users, each user's (y, n) being a count's (total, 1), a "
           "duration's (sum, number of observations) or a ratio's (numerator, denominator); "
           "se² = Σ(y_u − r·n_u)² / (U·(U−1)·n̄²); r ± t[0.975; U−1]·se, the lower end cut "
           "at 0 for a quantity that cannot be negative. For a count it is the t interval "
           "of the mean of the users' totals.", (_T, _RATIO)),
    Method("t+garwood", "t ∪ Garwood",
           "a count with fewer than 10 events: the t interval widened to the exact Poisson "
           "(Garwood) interval",
           "a count with fewer than 10 events over all users: the union of the t interval "
           "above and the exact Poisson interval of the total k over U users, "
           "[χ²(0.025; 2k)/2, χ²(0.975; 2k+2)/2] / U (0 for the lower end when k = 0).",
           (_T, _GARWOOD)),
    Method("t+garwood-rate", "t ∪ Garwood rate",
           "a ratio of counts with fewer than 10 numerator events: the t interval widened to "
           "the exact Poisson interval of the events per trial",
           "a ratio of two counts not declared a proportion (alarms per dose due) with fewer "
           "than 10 numerator events over all users: the union of the t interval above and "
           "the exact Poisson interval of the k events over the Σn trials of the "
           "denominator, [χ²(0.025; 2k)/2, χ²(0.975; 2k+2)/2] / Σn (0 for the lower end "
           "when k = 0).",
           (_T, _GARWOOD, _ULM)),
    Method("wilson-neff", "Wilson, eff. n",
           "a proportion of counts: Wilson's score interval on the effective number of trials "
           "(design effect of users who differ)",
           "a proportion of counts pooled over users (a ratio the spec declares a proportion, "
           "Proportion=\"true\"; an activity's omissions or errors per offer): "
           "p = Σy/Σn; the binomial variance "
           "v_bin = p(1−p)/Σn and the cluster-robust variance v_users (as for t); "
           "v = v_bin + (t[0.975; U−1]/z[0.975])²·max(0, v_users − v_bin); the Wilson score "
           "interval of p on n_eff = p(1−p)/v trials (Σn when p is 0 or 1 or U < 2). With 1 or "
           "2 events the lower end is at most χ²(0.05; 2k)/2 / Σn (and likewise the upper end "
           "with 1 or 2 non-events).",
           (_WILSON, "Kish (1965), Survey Sampling (design effect)",
            "Korn & Graubard (1998), Survey Methodology 24:193–201",
            "Brown, Cai & DasGupta (2001), Stat Sci 16:101–133")),
    Method("clopper-pearson", "Clopper–Pearson",
           "a share of users: the exact binomial interval",
           "a share of users k of U (users with any event, users affected, a subgroup's "
           "share): [B(0.025; k, U−k+1), B(0.975; k+1, U−k)], B the beta quantile.", (_CP,)),
    Method("garwood+t", "Garwood ∪ t",
           "violations per user-day: the exact Poisson interval widened to the cluster-robust t "
           "interval",
           "a monitor's violations per user-day: the union of the exact Poisson interval of "
           "the violations over U·days user-days and the cluster-robust t interval of the "
           "users' violations per day (right when violations cluster in some users).",
           (_GARWOOD, _T)),
    Method("paired-t", "paired t",
           "a difference of two designs on the same users: t on the per-user linearised "
           "differences",
           "a difference of two designs on the same users: the per-user linearised "
           "contributions d_u = (y_Bu − r_B·n_Bu)/n̄_B − (y_Au − r_A·n_Au)/n̄_A; "
           "(r_B − r_A) ± t[0.975; U−1]·sd(d)/√U.", (_T,)),
    Method("paired-t+garwood", "paired t ∪ Garwood",
           "a difference of counts with fewer than 10 discordant events: paired t widened to the "
           "Garwood bounds of the events added and removed",
           "a difference of counts with fewer than 10 discordant events (up events more in "
           "the second design, down fewer, over N = Σn): the union of the paired t interval and "
           "[(L_up − U_down)/N, (U_up − L_down)/N], L and U the Garwood bounds.",
           (_T, _GARWOOD)),
    Method("welch-t", "Welch t",
           "a difference of two designs as if on different users: Welch's t",
           "a difference of two designs as if the designs had run on different users: "
           "(r_B − r_A) ± t[0.975; ν]·√(v_A + v_B), v the cluster-robust variances, "
           "ν Welch's degrees of "
           "freedom (v_A + v_B)² / ((v_A² + v_B²)/(U−1)).",
           (_T, "Welch (1947), Biometrika 34:28–35")),
    Method("paired-t-few", "paired t, few",
           "a difference of durations with fewer than 10 users who differ: paired t on their "
           "number − 1 df",
           "a difference of durations when fewer than 10 users differ between the designs (on "
           "common random numbers the others are identical): the paired t interval on "
           "(differing users − 1) degrees of freedom; no interval with fewer than 2.",
           (_T,)),
)}


def describe(ids: Iterable[str]) -> dict[str, dict[str, Any]]:
    """The methods ``ids`` names, by id (in the table's order), as plain data for JSON."""
    wanted = set(ids)
    return {m.id: {"name": m.name, "summary": m.summary, "definition": m.definition,
                   "references": list(m.references)}
            for m in METHODS.values() if m.id in wanted}


def methods_in(doc: Any, keys: Iterable[str] | None = None) -> list[str]:
    """Every ``…_method`` id anywhere in a summary (nested dicts and lists; only under the
    names ``keys`` when given), in the table's order: what a reader of that summary needs
    defined."""
    found: set[str] = set()
    only = None if keys is None else set(keys)

    def walk(node: Any) -> None:
        if isinstance(node, Mapping):
            for key, value in node.items():
                if (isinstance(key, str) and key.endswith("_method") and value in METHODS
                        and (only is None or key in only)):
                    found.add(value)
                else:
                    walk(value)
        elif isinstance(node, list | tuple):
            for value in node:
                walk(value)

    walk(doc)
    return [m for m in METHODS if m in found]
