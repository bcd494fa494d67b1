"""A model fitted from a few persons, checked on new persons of the same population, is not
called a misfit more often than the stated level (issue 30: fit-then-check).

References nobody here wrote:

* the posterior of a normal population's mean and variance from n values under the
  reference prior p(mu, V) ∝ 1/V: V | data ~ (n - 1) s² / χ²(n - 1), mu | V ~ N(x̄, V / n),
  so that (mu - x̄) / (s / √n) ~ Student's t with n - 1 degrees of freedom (Gelman et al.,
  *Bayesian Data Analysis*, 3rd ed., §3.2);
* its consequence, the prediction interval of the mean of m future values,
  x̄ ± t(n - 1) s √(1/m + 1/n) (Hahn & Meeker 1991, *Statistical Intervals*): a check that
  places new people's mean in a narrower interval calls a correct model a misfit more often
  than its level says.

A percentile bootstrap of the persons (what the redraws of a population's centre and spread
were) has neither tail: its centre draws spread like a normal with (n - 1)/n of the
variance, and its variance draws centre on the estimate.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy import stats

from opspec.commands.fit import fitted_text
from opspec.commands.model_check import CheckOptions, check_model
from opspec.usermodels import load_user_model
from opspec.usermodels.bootstrap import parameter_draws
from opspec.usermodels.fitting import fit_traces

from tests.usermodels.test_fit_persons import write_session

CENTRE = "activities.hear.omission.probability"
SPREAD = "vary.activities.hear.omission.probability.sd"


def _persons(folder: Path, rates: list[float], prompts: int, rng: np.random.Generator,
             first: int = 0) -> list[Path]:
    """One session per person: ``prompts`` alarms, each missed with the person's rate."""
    return [write_session(folder / f"P{first + i:02d}.jsonl", [],
                          list(rng.random(prompts) >= q), person=f"P{first + i:02d}")
            for i, q in enumerate(rates)]


def test_a_populations_centre_is_redrawn_with_students_t_tails(tmp_path: Path) -> None:
    """Eight persons with clearly different omission rates: the redrawn centre of the
    population, standardised by the persons' sd over √8, has the tails of t(7) (its 97.5 %
    point 2.36), not those of a normal (1.96) — a percentile bootstrap of eight persons
    gives about 1.96 · √(7/8) = 1.83."""
    rng = np.random.default_rng(4)
    rates = [0.05, 0.1, 0.15, 0.2, 0.3, 0.35, 0.45, 0.5]
    result = fit_traces(_persons(tmp_path, rates, 200, rng), name="fitted")
    draws = parameter_draws(result, 4000, seed=1)
    assert draws is not None and SPREAD in draws.parameters
    counts = result.observations.counts_by_person(result.observations.user_omissions["hear"])
    person_rates = np.array([k / n for k, n in counts.values()])
    centre = np.array([row[draws.parameters.index(CENTRE)] for row in draws.draws])
    standardised = (centre - person_rates.mean()) / (person_rates.std(ddof=1) / math.sqrt(8))
    q975 = float(np.quantile(np.abs(standardised), 0.95))
    assert abs(q975 - stats.t.ppf(0.975, 7)) < 0.2, q975
    # the variance a redraw takes has the scaled inverse chi-square's median
    spread = np.array([row[draws.parameters.index(SPREAD)] for row in draws.draws])
    sampling = np.mean(person_rates * (1 - person_rates) / (np.array(
        [n for _, n in counts.values()]) - 1))
    total = np.median(spread ** 2 + sampling)
    expected = 7 * person_rates.var(ddof=1) / stats.chi2.median(7)
    assert abs(total / expected - 1) < 0.08, (total, expected)


def test_a_shared_rate_and_time_are_redrawn_with_students_t_tails(tmp_path: Path) -> None:
    """Eight persons who do not differ (one omission rate 0.15, one walk time for all): the
    fit writes no population, and a new group's rate and log walk time are predicted from
    eight persons as a t(7) interval says (Hahn & Meeker 1991) — the redrawn rate and
    log-median, standardised by the persons' own values' sd over √8, have the tails of t(7)
    (97.5 % point 2.36), where a percentile bootstrap of the eight gives about 1.83."""
    rng = np.random.default_rng(7)
    paths = [write_session(tmp_path / f"P{i:02d}.jsonl",
                           list(np.exp(rng.normal(math.log(60), 0.3, 40))),
                           list(rng.random(200) >= 0.15), person=f"P{i:02d}")
             for i in range(8)]
    result = fit_traces(paths, name="fitted")
    assert result.model.population is None
    draws = parameter_draws(result, 4000, seed=1)
    assert draws is not None and draws.resampled == "persons"
    obs = result.observations
    counts = obs.counts_by_person(obs.user_omissions["hear"])
    own = {"activities.hear.omission.probability":
           np.array([k / n for k, n in counts.values()]),
           # one session per person: a session's walks are that person's
           "activities.walk.duration.median": np.log([np.mean(v) for v in
                                                       obs.user_durations["walk"].values()])}
    for name, values in own.items():
        column = np.array([row[draws.parameters.index(name)] for row in draws.draws])
        estimate = draws.estimates[draws.parameters.index(name)]
        shift = np.log(column / estimate) if "duration" in name else column - estimate
        standardised = shift / (values.std(ddof=1) / math.sqrt(8))
        q975 = float(np.quantile(np.abs(standardised), 0.95))
        assert abs(q975 - stats.t.ppf(0.975, 7)) < 0.2, (name, q975)
