"""The posterior of a rate over persons (hierarchical beta-binomial, Gelman et al., *Bayesian
Data Analysis*, 3rd ed., §5.3): drawn from many persons of a known beta population, it
finds that population; with nothing to learn from it says so."""

from __future__ import annotations

import numpy as np

from opspec.usermodels.rate_posterior import rate_posterior


def test_many_persons_of_a_known_beta_population_are_recovered() -> None:
    """300 persons, 80 offers each, own rates ~ Beta with mean 0.2 and sd 0.1: the
    posterior's draws of the population's mean and sd lie around the truth, and are tight
    (a mean from 300 persons is known to about 0.1 / √300 ≈ 0.006)."""
    rng = np.random.default_rng(11)
    mean, sd = 0.2, 0.1
    concentration = mean * (1 - mean) / sd ** 2 - 1
    own = rng.beta(mean * concentration, (1 - mean) * concentration, 300)
    counts = [(int(rng.binomial(80, q)), 80) for q in own]
    posterior = rate_posterior(counts)
    assert posterior is not None and posterior.persons == 300
    draws = np.array([posterior.draw(np.random.default_rng(i)) for i in range(400)])
    means, sds = draws[:, 0], draws[:, 1]
    assert abs(np.median(means) - mean) < 0.015 and means.std() < 0.01
    assert abs(np.median(sds) - sd) < 0.015 and sds.std() < 0.01


def test_nothing_to_learn_a_rate_from() -> None:
    assert rate_posterior([(3, 40)]) is None                 # one person: no population
    assert rate_posterior([(0, 40), (0, 30)]) is None        # no event at all
    assert rate_posterior([(40, 40), (30, 30)]) is None      # nothing but events
    assert rate_posterior([(2, 0), (1, 30), (0, 30)]) is not None   # no offer: left out
