"""Which interval for a proportion over users? Coverage of the candidates by simulation (issue 19).

    python benchmarks/proportion_coverage.py [--repetitions 20000] [--seed 2]

A numpy model of what an evaluation reduces a proportion to: per user ``u`` a number of
events ``y_u`` out of ``n_u`` trials (missed out of due doses), ``y_u ~ Binomial(n_u, p_u)``.
Users who differ only by chance have one ``p`` (the reference user's missed-dose probability,
0.3456 % with three alarms and 0.0519 % with four, ``shared/bench/analytic.py``; 30 days = 120
doses, 7 days = 28); a population whose omission probability varies has ``p_u ~ Beta`` with a
given mean and sd, and the truth is the Beta mean. It prints the share of repetitions whose
95 % interval covers the truth, per case and number of users, for:

- ``t``: the cluster-robust (ratio-estimator) t interval alone;
- ``old``: the wider of ``t`` and the pooled Wilson interval below 10 events (opspec before);
- ``wilson``: Wilson on the pooled trials (every dose independent);
- ``kg``: Wilson on Korn & Graubard's (1998) effective sample size ``n/deff`` (deff >= 1);
- ``kg-df``: the same with their degrees-of-freedom adjustment ``n_eff·(z/t[U-1])²``;
- ``opspec``: :func:`opspec.statistics.proportions.proportion_interval` — ``kg`` with the
  adjustment applied to the between-user excess of the variance only, and Brown, Cai &
  DasGupta's (2001) Poisson bound for 1 or 2 events (checked here to give the same bounds
  as the vectorised formula on the first repetitions of every case).

Seconds of CPU; the ``interval_coverage`` benchmark runs the real evaluations.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from opspec.statistics.proportions import MODIFIED_WILSON_EVENTS, proportion_interval

P_THREE_ALARMS = 0.0034562262209500982
P_FOUR_ALARMS = 0.0005186876829259557
Z = float(stats.norm.ppf(0.975))

Draw = Callable[[np.random.Generator, tuple[int, int]], np.ndarray]


def wilson(events: np.ndarray, trials: np.ndarray, z: float | np.ndarray = Z
           ) -> tuple[np.ndarray, np.ndarray]:
    p = events / trials
    a = z * z / trials
    centre = (p + a / 2) / (1 + a)
    half = z * np.sqrt(p * (1 - p) / trials + a / (4 * trials)) / (1 + a)
    return (np.where(p <= 0, 0.0, np.maximum(centre - half, 0.0)),
            np.where(p >= 1, 1.0, np.minimum(centre + half, 1.0)))


def intervals(y: np.ndarray, n: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every candidate's bounds for each row (one repetition) of users' (y, n)."""
    users = y.shape[1]
    events, trials = y.sum(1), n.sum(1)
    p = events / trials
    nbar = trials / users
    cluster = ((y - p[:, None] * n) ** 2).sum(1) / (users * (users - 1) * nbar ** 2)
    t = float(stats.t.ppf(0.975, users - 1))
    t_half = t * np.sqrt(cluster)
    t_ci = (np.maximum(p - t_half, 0.0), p + t_half)
    pooled = wilson(events, trials)
    rare = np.minimum(events, trials - events) < 10
    inner = (p > 0) & (p < 1)
    binomial = p * (1 - p) / trials
    deff = np.where(inner, cluster / np.where(inner, binomial, 1.0), 1.0)
    kg_n = trials / np.maximum(deff, 1.0)
    variance = binomial + (t / Z) ** 2 * np.maximum(cluster - binomial, 0.0)
    ours_n = np.where(inner, p * (1 - p) / np.where(inner, variance, 1.0), trials)
    ours_low, ours_high = wilson(p * ours_n, ours_n)
    for k in range(1, MODIFIED_WILSON_EVENTS + 1):     # Brown, Cai & DasGupta near 0 and n
        bound = float(stats.chi2.ppf(0.05, 2 * k)) / 2 / trials
        ours_low = np.where(events == k, np.minimum(ours_low, bound), ours_low)
        ours_high = np.where(trials - events == k, np.maximum(ours_high, 1 - bound), ours_high)
    return {
        "t": t_ci,
        "old": (np.where(rare, np.minimum(t_ci[0], pooled[0]), t_ci[0]),
                np.where(rare, np.maximum(t_ci[1], pooled[1]), t_ci[1])),
        "wilson": pooled,
        "kg": wilson(p * kg_n, kg_n),
        "kg-df": wilson(p * kg_n, kg_n, t),
        "opspec": (ours_low, ours_high),
    }


def cases() -> list[tuple[str, int, Draw, float]]:
    def same(p: float) -> Draw:
        return lambda rng, shape: np.full(shape, p)

    def beta(mean: float, sd: float) -> Draw:
        k = mean * (1 - mean) / (sd * sd) - 1
        return lambda rng, shape: rng.beta(mean * k, (1 - mean) * k, shape)

    return [("alike 0.35 % (A), 30 d", 120, same(P_THREE_ALARMS), P_THREE_ALARMS),
            ("alike 0.05 % (B), 30 d", 120, same(P_FOUR_ALARMS), P_FOUR_ALARMS),
            ("alike 0.35 % (A), 7 d", 28, same(P_THREE_ALARMS), P_THREE_ALARMS),
            ("alike 0.05 % (B), 7 d", 28, same(P_FOUR_ALARMS), P_FOUR_ALARMS),
            ("alike 5 %, 30 d", 120, same(0.05), 0.05),
            ("Beta 0.35 % sd 0.35 %", 120, beta(0.0035, 0.0035), 0.0035),
            ("Beta 0.35 % sd 1 %", 120, beta(0.0035, 0.01), 0.0035),
            ("Beta 2 % sd 2 %", 120, beta(0.02, 0.02), 0.02),
            ("Beta 10 % sd 8 %", 120, beta(0.10, 0.08), 0.10)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repetitions", type=int, default=20_000)
    parser.add_argument("--users", type=int, nargs="+", default=[10, 20, 100])
    parser.add_argument("--seed", type=int, default=2)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    names = None
    for users in args.users:
        for label, trials, draw, truth in cases():
            n = np.full((args.repetitions, users), float(trials))
            y = rng.binomial(trials, draw(rng, (args.repetitions, users))).astype(float)
            found = intervals(y, n)
            for row in range(min(50, args.repetitions)):      # the shipped function agrees
                shipped = proportion_interval(list(zip(y[row], n[row], strict=True)))
                ours = (found["opspec"][0][row], found["opspec"][1][row])
                assert np.allclose(shipped, ours, rtol=1e-9, atol=1e-15), (shipped, ours)
            if names is None:
                names = list(found)
                print(f"95 % coverage over {args.repetitions} repetitions (seed {args.seed})")
                print(f"{'case':<24} {'users':>5} " + " ".join(f"{k:>7}" for k in names))
            cover = [np.mean((lo <= truth) & (truth <= hi)) for lo, hi in found.values()]
            print(f"{label:<24} {users:>5} " + " ".join(f"{100 * c:>6.1f}%" for c in cover),
                  flush=True)


if __name__ == "__main__":
    main()
