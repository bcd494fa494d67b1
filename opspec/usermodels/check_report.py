"""What a model check found (``opspec model-check``): each item checked, its Holm-adjusted
verdict, and the report printed and written as JSON.

:class:`CheckItem` is one thing checked (a duration, a rate, a spec's outcome metric) with
what was observed against what the model predicts for a group of this many people;
:func:`finish` adjusts the items' p-values over all of them (Holm's step-down,
:mod:`opspec.usermodels.holm`) and calls those at or under the level misfits;
:class:`CheckReport` is every item, the family-wise statement and the notes on what was not
checked. The checks themselves are :mod:`opspec.usermodels.checking`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from opspec.usermodels.holm import holm_adjust

__all__ = ["CheckItem", "CheckReport", "finish"]


@dataclass(frozen=True)
class CheckItem:
    """One thing checked: its test, statistic, p-value and what was observed and predicted.

    ``observed``/``predicted`` are short summaries (``predicted`` with a 95 % interval
    ``low``/``high`` for what a group of this many people would show); ``figure`` holds what
    the report draws (quantiles for a QQ plot, a predictive distribution for an interval).
    ``p_holm`` and ``misfit`` are set by :func:`finish` once all items are known.
    """

    name: str
    kind: str                    # duration | omission | commission | repetition | metric
    activity: str | None
    test: str
    statistic: float
    p: float
    persons: int
    n: int
    observed: Mapping[str, float]
    predicted: Mapping[str, float]
    unit: str = ""
    figure: Mapping[str, Any] = field(default_factory=dict)
    p_holm: float = math.nan
    misfit: bool = False

    def comparison(self) -> str:
        """What was observed against what the model predicts for a group of this size."""
        o, p = self.observed, self.predicted
        fmt = _fmt_rate if self.kind in _RATES else _fmt_value
        return (f"observed {self.observed_label} {fmt(o['value'], self.unit)}, predicted "
                f"{fmt(p['value'], self.unit)} (95 % of groups of {self.persons}: "
                f"[{fmt(p['low'], self.unit)}, {fmt(p['high'], self.unit)}])")

    def describe(self) -> str:
        """One line: the verdict, what was observed against what was predicted, the test."""
        what = self.comparison()
        verdict = "MISFIT" if self.misfit else "fits  "
        unit = f" {self.unit}" if self.kind == "metric" and self.unit else ""
        return (f"{verdict} {self.name}: {what}; {self.test}: {self.statistic_label} = "
                f"{self.statistic:.4g}{unit}, "
                f"p = {_fmt_p(self.p)}, Holm-adjusted p = {_fmt_p(self.p_holm)}")

    @property
    def pooled(self) -> bool:
        """A rate item tested on the pooled count (one rate for everyone)."""
        return self.test.startswith("exact binomial")

    @property
    def statistic_label(self) -> str:
        if self.kind in _RATES:
            return "count" if self.pooled else "mean rate"
        return {"duration": "A²", "metric": "mean"}.get(self.kind, "value")

    @property
    def observed_label(self) -> str:
        if self.kind in _RATES:
            return "rate" if self.pooled else "mean rate per person"
        return {"duration": "median", "metric": "mean per person"}.get(self.kind, "value")

    def to_json(self) -> dict[str, Any]:
        return {"item": self.name, "kind": self.kind, "activity": self.activity,
                "test": self.test, "statistic": _finite(self.statistic), "p": self.p,
                "p_holm": self.p_holm, "misfit": self.misfit, "persons": self.persons,
                "n": self.n, "unit": self.unit or None,
                "observed": {k: _finite(v) for k, v in self.observed.items()},
                "predicted": {k: _finite(v) for k, v in self.predicted.items()}}


_RATES = ("omission", "commission", "repetition")


def _finite(value: float) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None


def _fmt_p(p: float) -> str:
    return "nan" if math.isnan(p) else f"{p:.3g}" if p >= 0.001 else f"{p:.1e}"


def _fmt_rate(value: float, unit: str) -> str:
    return f"{100 * value:.1f} %"


def _fmt_value(value: float, unit: str) -> str:
    return f"{value:.4g}" + (f" {unit}" if unit else "")


@dataclass(frozen=True)
class CheckReport:
    """Every item checked, Holm-adjusted at ``level``, and what was not checked (``notes``)."""

    items: tuple[CheckItem, ...]
    level: float
    persons: int
    sessions: int
    replicates: int
    seed: int
    uncertainty: str
    notes: tuple[str, ...] = ()
    #: how many of the persons checked the model was fitted on (its ``[fitted_on]`` table)
    fitted_on: int = 0

    @property
    def misfits(self) -> tuple[CheckItem, ...]:
        return tuple(i for i in self.items if i.misfit)

    @property
    def fits(self) -> bool:
        return not self.misfits

    def method(self) -> str:
        return (f"Holm's step-down adjustment over {len(self.items)} item(s): the chance that "
                f"any item of a correct model is called a misfit is at most {self.level:g}")

    def lines(self) -> list[str]:
        out = [item.describe() for item in self.items]
        out.append(f"family-wise error: {self.method()}")
        out.extend(f"note: {n}" for n in self.notes)
        if self.misfits:
            names = ", ".join(i.name for i in self.misfits)
            out.append(f"verdict: {len(self.misfits)} of {len(self.items)} item(s) misfit "
                       f"at family-wise level {self.level:g}: {names}")
        else:
            out.append(f"verdict: {self._fits_verdict()}")
        return out

    def _fits_verdict(self) -> str:
        """What no misfit says: that the model fits these people, and — when they were
        all in its fit — only that it reproduces what it was fitted on."""
        none = (f"none of {len(self.items)} item(s) misfits at family-wise level "
                f"{self.level:g}")
        if self.fitted_on >= self.persons > 0:
            return (f"{none}, but all {self.persons} person(s) checked are among those the "
                    "model was fitted on: it reproduces the people it was fitted on, which "
                    "says nothing of how it predicts new people")
        if self.fitted_on:
            return (f"the model fits these {self.persons} person(s), {self.fitted_on} of "
                    f"them among those it was fitted on: {none}")
        return f"the model fits these {self.persons} person(s): {none}"

    def to_json(self) -> dict[str, Any]:
        return {"fits": self.fits, "level": self.level,
                "family_wise": {"method": "holm", "items": len(self.items),
                                "statement": self.method()},
                "persons": self.persons, "persons_fitted_on": self.fitted_on,
                "sessions": self.sessions,
                "replicates": self.replicates, "seed": self.seed,
                "parameter_uncertainty": self.uncertainty,
                "misfits": [i.name for i in self.misfits],
                "items": [i.to_json() for i in self.items], "notes": list(self.notes)}


def finish(items: Sequence[CheckItem], level: float) -> tuple[CheckItem, ...]:
    """``items`` with their Holm-adjusted p-values and verdicts at family-wise ``level``."""
    adjusted = holm_adjust([i.p for i in items])
    return tuple(replace(i, p_holm=a, misfit=a <= level) for i, a in zip(items, adjusted,
                                                                          strict=True))
