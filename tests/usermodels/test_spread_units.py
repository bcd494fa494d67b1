"""The between-user lines of `opspec fit` give the persons' mean durations in seconds."""

from __future__ import annotations

import numpy as np

from opspec.usermodels.spread import duration_spread


def test_user_mean_durations_carry_their_unit() -> None:
    rng = np.random.default_rng(1)
    per_user = {f"P{i}": list(rng.lognormal(np.log(20 + 5 * i), 0.3, 12)) for i in range(5)}
    spread = duration_spread(per_user, min_per_user=10)
    assert spread is not None
    line = next(x for x in spread.comment().splitlines() if "user mean durations" in x)
    means = spread.user_means
    assert line == ("  user mean durations: " + ", ".join(
        f"{k} {means[k]:.4g} s" for k in ("mean", "p5", "p50", "p95")))


def test_a_metrics_mean_in_the_check_carries_its_unit() -> None:
    from opspec.usermodels.check_report import CheckItem, finish

    item = finish([CheckItem("metric report_latency_s", "metric", None,
                             "predictive interval of the mean of 2", 13.68, 0.478, 2, 2,
                             {"value": 13.68}, {"value": 12.46, "low": 9.09, "high": 16.43},
                             unit="s")], 0.05)[0]
    assert "predictive interval of the mean of 2: mean = 13.68 s, p = 0.478" in item.describe()
