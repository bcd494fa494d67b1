"""Between-user variation, estimated per user and then pooled (``opspec fit``).

Each user (a run of a trace: one simulated or recorded person) with at least ``min_per_user``
observations gets their own estimate; the spread of those estimates over users is the
observed variation, which is *more* than the variation between people, because every user's
estimate has its own sampling error. The between-user part is the observed variance minus
the mean sampling variance (the method of moments of random-effects meta-analysis,
DerSimonian & Laird 1986, and of the beta-binomial):

* durations: ``L_u = ln(mean duration of user u)``; ``var(L_u)`` observed over users minus
  the mean of ``s_u^2 / (n_u * mean_u^2)`` (the delta-method variance of a log mean) is the
  between-user variance of the log *scale* of the user's durations, whatever the family. The
  per-user distribution is then a factor ``F ~ lognormal(median 1, sigma = tau)`` multiplying
  every duration of that user;
* omissions: per-user rates ``p_u = k_u / n_u``; their mean ``p`` is the centre of the
  per-user distribution (not the pooled ``sum k / sum n``: a missed prompt is offered again,
  so the forgetful are offered most and a pooled rate weighs them more than the per-person
  rate a population draws); ``var(p_u)`` minus ``mean(p_u (1 - p_u) / (n_u - 1))`` (each
  term an unbiased estimate of that user's sampling variance) is the between-user variance;
  the per-user distribution is ``Beta(a, b)`` with that mean and variance. A chi-square test of homogeneity says whether users differ at all.

Both come with a 95 % interval from a seeded percentile bootstrap over users (the same
traces give the same interval). Fewer than 3 users with enough data: no estimate.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["DurationSpread", "OmissionSpread", "PersonMoments",
           "duration_moments", "duration_spread", "omission_moments",
           "omission_spread"]

#: bootstrap resamples of users for the intervals of the between-user spread
RESAMPLES = 999


def _summary(values: Sequence[float] | np.ndarray) -> dict[str, float]:
    a = np.asarray(values, dtype=float)
    return {"mean": float(a.mean()), "sd": float(a.std(ddof=1)) if a.size > 1 else 0.0,
            "p5": float(np.percentile(a, 5)), "p50": float(np.percentile(a, 50)),
            "p95": float(np.percentile(a, 95))}


def _bootstrap(statistic: Any, n_users: int, seed: int = 0) -> tuple[float, float]:
    rng = np.random.default_rng(seed)
    draws = [statistic(rng.integers(0, n_users, n_users)) for _ in range(RESAMPLES)]
    return float(np.percentile(draws, 2.5)), float(np.percentile(draws, 97.5))


@dataclass(frozen=True)
class DurationSpread:
    """How much users differ in one activity's durations."""

    users: int
    observed_sd: float            # sd over users of ln(user mean)
    sampling_sd: float            # the part sampling error alone explains (root mean var)
    between_sd: float             # tau: sd of ln(scale) between users
    between_sd_ci: tuple[float, float]
    user_means: dict[str, float] = field(default_factory=dict)    # p5/p50/p95 of means
    parameters: dict[str, dict[str, float]] = field(default_factory=dict)  # per-user fits
    min_per_user: int = 10        # the observations a user needed to count

    def to_json(self) -> dict[str, Any]:
        return {"users": self.users, "observed_sd_log_mean": self.observed_sd,
                "sampling_sd_log_mean": self.sampling_sd,
                "between_user_sd_log_scale": self.between_sd,
                "between_user_sd_ci95": list(self.between_sd_ci),
                "per_user_distribution": {"kind": "lognormal", "median": 1.0,
                                          "sigma": self.between_sd,
                                          "applies_to": "a factor on every duration"},
                "user_mean_duration": self.user_means,
                "per_user_parameters": self.parameters}

    def comment(self) -> str:
        lo, hi = self.between_sd_ci
        lines = [(f"between users ({self.users} persons with enough data): sd of ln(mean "
                 f"duration) {self.observed_sd:.3f} observed, {self.sampling_sd:.3f} expected "
                 f"from sampling alone -> between-user sd of ln(scale) {self.between_sd:.3f} "
                 f"(95 % bootstrap interval [{lo:.3f}, {hi:.3f}])"),
                 (f"  per-user distribution: every duration x F, F ~ lognormal(median 1, "
                 f"sigma {self.between_sd:.3f})"),
                 "  user mean durations: " + ", ".join(
                     f"{k} {v:.4g} s" for k, v in self.user_means.items() if k != "sd")]
        for name, s in self.parameters.items():
            lines.append(f"  per-user {name}: mean {s['mean']:.4g}, sd {s['sd']:.4g}, "
                         f"p5 {s['p5']:.4g}, median {s['p50']:.4g}, p95 {s['p95']:.4g}")
        return "\n".join(lines)


def duration_spread(per_user: Mapping[Any, Sequence[float]], *, min_per_user: int = 10,
                    family: str | None = None, seed: int = 0) -> DurationSpread | None:
    """Between-user variation of durations (module docstring); ``family`` (a name of
    :data:`opspec.usermodels.families.FAMILIES`) is also fitted per user to report the
    spread of its parameters."""
    groups = _duration_groups(per_user.values(), min_per_user)
    if len(groups) < 3:
        return None
    means, logs, within = _log_means(groups)

    def between(idx: np.ndarray) -> float:
        return math.sqrt(max(0.0, float(np.var(logs[idx], ddof=1)) - float(within[idx].mean())))

    every = np.arange(len(groups))
    parameters: dict[str, dict[str, float]] = {}
    if family is not None:
        from opspec.usermodels.families import fit_family

        fits = [fit_family(family, g) for g in groups]
        by_name: dict[str, list[float]] = {}
        for fit in fits:
            if fit is None:
                continue
            for name, value in fit.named_parameters().items():
                by_name.setdefault(name, []).append(value)
        parameters = {name: _summary(v) for name, v in by_name.items() if len(v) >= 3}
    return DurationSpread(
        users=len(groups), observed_sd=float(np.std(logs, ddof=1)),
        sampling_sd=math.sqrt(float(within.mean())), between_sd=between(every),
        between_sd_ci=_bootstrap(between, len(groups), seed),
        user_means=_summary(means), parameters=parameters, min_per_user=min_per_user)


def _duration_groups(per_user: Iterable[Sequence[float]], min_per_user: int
                     ) -> list[np.ndarray]:
    return [np.asarray(v, dtype=float) for v in per_user
            if len(v) >= min_per_user and np.all(np.asarray(v, dtype=float) > 0)]


def _log_means(groups: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    means = np.array([g.mean() for g in groups])
    within = np.array([g.var(ddof=1) / (g.size * g.mean() ** 2) for g in groups])
    return means, np.log(means), within


@dataclass(frozen=True)
class PersonMoments:
    """What a between-person spread is estimated from: ``users`` persons' own values (the
    log of a person's mean duration, or a person's own omission rate), their ``observed``
    variance over persons (ddof 1) and the ``sampling`` part of it (the mean of each
    person's own sampling variance). The between-person variance is their difference."""

    users: int
    observed: float
    sampling: float

    @property
    def between_sd(self) -> float:
        return math.sqrt(max(0.0, self.observed - self.sampling))


def duration_moments(per_user: Iterable[Sequence[float]], *, min_per_user: int = 10
                     ) -> PersonMoments | None:
    """The persons' log mean durations' variance and its sampling part (None: fewer than 3
    persons with ``min_per_user`` positive durations)."""
    groups = _duration_groups(per_user, min_per_user)
    if len(groups) < 3:
        return None
    _, logs, within = _log_means(groups)
    return PersonMoments(len(groups), float(np.var(logs, ddof=1)), float(within.mean()))


def omission_moments(per_user: Iterable[tuple[int, int]], *, min_per_user: int = 10
                     ) -> PersonMoments | None:
    """The persons' own omission rates' variance and its sampling part (None: fewer than 3
    persons with ``min_per_user`` offers)."""
    found = _omission_counts(per_user, min_per_user)
    if found is None:
        return None
    k, n = found
    rates, sampling = _rates(k, n)
    return PersonMoments(len(rates), float(np.var(rates, ddof=1)), float(sampling.mean()))


def _omission_counts(per_user: Iterable[tuple[int, int]], min_per_user: int
                     ) -> tuple[np.ndarray, np.ndarray] | None:
    """The ``(omitted, offered)`` counts of the persons with ``min_per_user`` offers, as
    arrays (None: fewer than 3 such persons)."""
    pairs = [(k, n) for k, n in per_user if n >= min_per_user]
    if len(pairs) < 3:
        return None
    return (np.array([p[0] for p in pairs], dtype=float),
            np.array([p[1] for p in pairs], dtype=float))


def _rates(k: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each person's own rate and its binomial sampling variance."""
    rates = k / n
    return rates, rates * (1 - rates) / np.maximum(n - 1, 1)


@dataclass(frozen=True)
class OmissionSpread:
    """How much users differ in how often they omit one activity."""

    users: int
    mean: float                   # the mean of the users' own rates (the beta's mean)
    observed_sd: float
    between_sd: float
    between_sd_ci: tuple[float, float]
    homogeneity_p: float          # chi-square test that every user has the same rate
    beta: tuple[float, float] | None   # (a, b) of the per-user distribution, None: no spread
    user_rates: dict[str, float] = field(default_factory=dict)
    min_per_user: int = 10        # the offers a user needed to count

    @property
    def varies(self) -> bool:
        """Users differ (one rate for all rejected at 5 %) and a beta describes them."""
        return self.homogeneity_p < 0.05 and self.beta is not None

    def to_json(self) -> dict[str, Any]:
        return {"users": self.users, "mean": self.mean, "observed_sd": self.observed_sd,
                "between_user_sd": self.between_sd,
                "between_user_sd_ci95": list(self.between_sd_ci),
                "homogeneity_p": self.homogeneity_p,
                "per_user_distribution": None if self.beta is None else {
                    "kind": "beta", "a": self.beta[0], "b": self.beta[1]},
                "user_rates": self.user_rates}

    def comment(self) -> str:
        lo, hi = self.between_sd_ci
        text = (f"omission between users ({self.users} persons): rates sd {self.observed_sd:.4f} "
                f"observed, between-user sd {self.between_sd:.4f} (95 % bootstrap interval "
                f"[{lo:.4f}, {hi:.4f}]); same rate for everyone: chi-square p = "
                f"{self.homogeneity_p:.3g}")
        if self.beta is not None:
            text += (f"\n  per-user distribution: p ~ Beta(a {self.beta[0]:.3g}, "
                     f"b {self.beta[1]:.3g})")
        return text + "\n  user rates: " + ", ".join(
            f"{k} {v:.4g}" for k, v in self.user_rates.items() if k != "sd")


def omission_spread(per_user: Mapping[Any, tuple[int, int]], *, min_per_user: int = 10,
                    seed: int = 0) -> OmissionSpread | None:
    """Between-user variation of an omission rate from per-user ``(omitted, answered)``."""
    found = _omission_counts(per_user.values(), min_per_user)
    if found is None:
        return None
    k, n = found
    rates, sampling = _rates(k, n)

    def between_var(idx: np.ndarray) -> float:
        return float(np.var(rates[idx], ddof=1)) - float(sampling[idx].mean())

    every = np.arange(len(rates))
    mean = float(rates.mean())
    var_b = max(0.0, between_var(every))
    beta = None
    if var_b > 0 and 0 < mean < 1 and var_b < mean * (1 - mean):
        concentration = mean * (1 - mean) / var_b - 1
        beta = (mean * concentration, (1 - mean) * concentration)
    from scipy import stats  # type: ignore[import-untyped]

    table = np.column_stack([k, n - k])
    if table.sum(axis=0).min() > 0:
        p_value = float(stats.chi2_contingency(table, correction=False)[1])
    else:
        p_value = 1.0
    return OmissionSpread(
        users=len(rates), mean=mean, observed_sd=float(np.std(rates, ddof=1)),
        between_sd=math.sqrt(var_b),
        between_sd_ci=_bootstrap(lambda idx: math.sqrt(max(0.0, between_var(idx))),
                                 len(rates), seed),
        homogeneity_p=p_value, beta=beta, user_rates=_summary(rates),
        min_per_user=min_per_user)
