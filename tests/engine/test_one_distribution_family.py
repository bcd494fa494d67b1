"""Activity durations and user models draw from one family of distributions (issue 18).

The engine's sampler for a declared duration is the user-model family's ``sample``: the same
kind and parameters give the same numbers from the same stream. The distributions themselves
are checked against scipy.stats (an implementation nobody here wrote).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from opspec.distributions import from_model
from opspec.engine.sampling import make_sampler
from opspec.model import DeclaredDistribution as Distribution
from opspec.usermodels.distributions import TruncatedNormal, make_distribution

DECLARED = [
    Distribution(kind="ConstantParameter", parameters=(("value", 4.0),)),
    Distribution(kind="NormalDistribution", parameters=(("mean", 30.0), ("standardDeviation", 5.0))),
    Distribution(kind="LogNormalDistribution", parameters=(("mean", 10.0), ("standardDeviation", 4.0))),
    Distribution(kind="UniformDistribution", parameters=(("min", 2.0), ("max", 5.0))),
    Distribution(kind="ExponentialDistribution", parameters=(("mean", 3.0),)),
    Distribution(kind="TriangularDistribution", parameters=(("min", 1.0), ("mode", 2.0), ("max", 6.0))),
    Distribution(kind="GammaDistribution", parameters=(("shape", 2.0), ("scale", 3.0))),
    Distribution(kind="WeibullDistribution", parameters=(("shape", 1.5), ("scale", 3.0))),
    Distribution(kind="TruncatedNormalDistribution",
                 parameters=(("mean", 30.0), ("standardDeviation", 5.0), ("min", 25.0), ("max", 40.0))),
    Distribution(kind="exgauss", parameters=(("mu", 1.0), ("sigma", 0.5), ("tau", 2.0))),
]


@pytest.mark.parametrize("declared", DECLARED, ids=[d.kind for d in DECLARED])
def test_engine_draws_what_the_user_model_family_draws(declared: Distribution) -> None:
    sampler = make_sampler(declared)
    family = from_model(declared)
    a, b = np.random.default_rng(7), np.random.default_rng(7)
    engine = [sampler(a) for _ in range(200)]
    model = [max(0.0, family.sample(b)) for _ in range(200)]
    assert engine == model


def test_a_normal_duration_is_truncated_at_zero_not_clipped() -> None:
    # mean 1 s, sd 2 s: a third of the normal lies below 0. Truncated (scipy.stats.truncnorm):
    # mean 2.018 s; clipped at 0 (the engine before the families were one): mean 1.396 s.
    sampler = make_sampler(Distribution(kind="NormalDistribution",
                                        parameters=(("mean", 1.0), ("standardDeviation", 2.0))))
    rng = np.random.default_rng(3)
    draws = np.array([sampler(rng) for _ in range(40_000)])
    reference = stats.truncnorm(a=-0.5, b=math.inf, loc=1.0, scale=2.0)
    assert draws.min() > 0.0
    se = reference.std() / math.sqrt(len(draws))
    assert abs(draws.mean() - reference.mean()) < 4 * se
    assert stats.kstest(draws, reference.cdf).pvalue > 0.001


def test_lognormal_mean_with_sigma_is_the_mean_of_the_duration() -> None:
    # lognormal(mean=60, sigma=0.5): E[X] = exp(mu + sigma²/2) = 60 (scipy's lognorm moments)
    dist = make_distribution({"kind": "lognormal", "mean": 60.0, "sigma": 0.5})
    reference = stats.lognorm(s=0.5, scale=60.0 * math.exp(-0.125))
    assert dist.mean == pytest.approx(reference.mean()) == pytest.approx(60.0)
    assert dist.quantile(0.9) == pytest.approx(reference.ppf(0.9))


def test_an_exgauss_duration_is_never_negative() -> None:
    sampler = make_sampler(Distribution(kind="exgauss",
                                        parameters=(("mu", 0.1), ("sigma", 1.0), ("tau", 0.2))))
    rng = np.random.default_rng(5)
    assert min(sampler(rng) for _ in range(5_000)) == 0.0


def test_bad_parameters_name_the_parameter() -> None:
    with pytest.raises(ValueError, match=r"GammaDistribution: shape: must be > 0, got -1"):
        make_sampler(Distribution(kind="GammaDistribution",
                                  parameters=(("shape", -1.0), ("scale", 1.0))))
    with pytest.raises(ValueError, match=r"unknown distribution 'Banana'"):
        make_sampler(Distribution(kind="Banana"))


def test_the_old_import_paths_name_the_same_classes() -> None:
    from opspec.distributions import TruncatedNormal as Home
    from opspec.usermodels.distbase import Distribution as Base
    from opspec.usermodels.parametric import TruncatedNormal as Parametric

    assert TruncatedNormal is Home is Parametric and issubclass(Home, Base)
