"""Statistics, in one home: every interval, proportion, percentile and statistical verdict of
opspec comes from here (spec tests, evaluations, user-model fitting, the engine's summaries).

* :mod:`~opspec.statistics.intervals` — one sample: proportions (Wilson, Clopper-Pearson),
  Poisson rates (Garwood), means (t, BCa bootstrap), quantiles (order statistics);
* :mod:`~opspec.statistics.clustered` — ratios over users, the independent replications of an
  evaluation (cluster-robust t), counts with rare events, hazards, paired differences;
* :mod:`~opspec.statistics.proportions` — a proportion pooled over users: Wilson's score
  interval on the effective number of trials;
* :mod:`~opspec.statistics.ratios` — a ratio metric's interval by its declaration in the spec
  (a proportion's or a ratio's, with few events the exact Poisson one);
* :mod:`~opspec.statistics.percentiles` — the two percentile conventions (interpolated,
  nearest rank);
* :mod:`~opspec.statistics.no_spread` — an interval of no width because every user gave the
  same value: how many users, and how large a share could still differ;
* :mod:`~opspec.statistics.claims` — deciding a claim "X >= b with 95 % confidence";
* :mod:`~opspec.statistics.methods` — how each interval is computed, in words, with its
  references (what the report, ``--json`` and the docs say).
"""

from opspec.statistics.clustered import (
    RARE_DISCORDANT,
    RARE_EVENTS,
    RatioEstimate,
    count_estimate,
    count_estimate_from_sums,
    hazard_estimate,
    paired_difference,
    ratio_estimate,
)
from opspec.statistics.intervals import (
    MEAN_METHODS,
    RATE_METHODS,
    Interval,
    mean_interval,
    normal_quantile,
    one_sided,
    poisson_interval,
    quantile_interval,
    rate_interval,
    t_quantile,
)
from opspec.statistics.proportions import effective_trials, proportion_interval

__all__ = [
    "MEAN_METHODS",
    "RARE_DISCORDANT",
    "RARE_EVENTS",
    "RATE_METHODS",
    "Interval",
    "RatioEstimate",
    "count_estimate",
    "count_estimate_from_sums",
    "effective_trials",
    "hazard_estimate",
    "mean_interval",
    "normal_quantile",
    "one_sided",
    "paired_difference",
    "poisson_interval",
    "proportion_interval",
    "quantile_interval",
    "rate_interval",
    "ratio_estimate",
    "t_quantile",
]
