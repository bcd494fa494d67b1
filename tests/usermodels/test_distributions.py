"""Distributions: sample moments against analytic moments, validation, BPSim adapter."""

from __future__ import annotations

import math

import numpy as np
import pytest

from opspec.errors import UserModelError
from opspec.model import DeclaredDistribution as ModelDistribution
from opspec.usermodels.distributions import (
    Distribution,
    LogNormal,
    ParameterError,
    from_model,
    make_distribution,
)

CASES = {
    "lognormal-median": {"kind": "lognormal", "median": 60.0, "sigma": 0.6},
    "lognormal-mu": {"kind": "lognormal", "mu": 1.0, "sigma": 0.3},
    "lognormal-mean-sd": {"kind": "lognormal", "mean": 10.0, "sd": 4.0},
    "gamma": {"kind": "gamma", "shape": 2.5, "scale": 3.0},
    "gamma-rate": {"kind": "gamma", "shape": 0.7, "rate": 2.0},
    "weibull": {"kind": "weibull", "shape": 1.7, "scale": 12.0},
    "normal-truncated-at-0": {"kind": "normal", "mean": 2.0, "sd": 3.0},
    "normal-bounded": {"kind": "normal", "mean": 5.0, "sd": 2.0, "low": 4.0, "high": 9.0},
    "normal-far-tail": {"kind": "normal", "mean": 0.0, "sd": 1.0, "low": 6.0},
    "exponential": {"kind": "exponential", "mean": 7.0},
    "exgauss": {"kind": "exgauss", "mu": 0.5, "sigma": 0.05, "tau": 0.3},
    "triangular": {"kind": "triangular", "low": 1.0, "mode": 2.0, "high": 6.0},
    "uniform": {"kind": "uniform", "low": 3.0, "high": 8.0},
    "constant": {"kind": "constant", "value": 4.2},
    "empirical": {"kind": "empirical", "values": [3.0, 5.0, 11.0, 12.5]},
    "empirical-jitter": {"kind": "empirical", "values": [30.0, 50.0, 80.0], "jitter": 2.0},
    "with-tail": {"kind": "with_tail", "base": {"kind": "uniform", "low": 1, "high": 2},
                  "tau": 0.5},
}


def _within_5_se(x: np.ndarray, dist: Distribution) -> None:
    n = x.size
    se_mean = math.sqrt(dist.var / n) if dist.var else 1e-12
    assert abs(x.mean() - dist.mean) <= 5 * se_mean + 1e-12, (x.mean(), dist.mean)
    # Standard error of the sample variance from the sample's own fourth central moment.
    dev2 = (x - x.mean()) ** 2
    se_var = float(dev2.std()) / math.sqrt(n)
    assert abs(x.var() - dist.var) <= 5 * se_var + 1e-9, (x.var(), dist.var)


@pytest.mark.parametrize("params", CASES.values(), ids=CASES.keys())
def test_vectorised_samples_match_the_analytic_mean_and_variance(params: dict) -> None:
    dist = make_distribution(params)
    _within_5_se(dist.sample_many(np.random.default_rng(7), 200_000), dist)


@pytest.mark.parametrize("params", CASES.values(), ids=CASES.keys())
def test_scalar_samples_match_the_analytic_mean_and_variance(params: dict) -> None:
    dist = make_distribution(params)
    rng = np.random.default_rng(11)
    _within_5_se(np.array([dist.sample(rng) for _ in range(20_000)]), dist)


@pytest.mark.parametrize("params", CASES.values(), ids=CASES.keys())
def test_toml_form_reads_back_to_the_same_distribution(params: dict) -> None:
    dist = make_distribution(params)
    again = make_distribution(dist.to_params())
    assert type(again) is type(dist)
    assert again.mean == pytest.approx(dist.mean, rel=1e-12)
    assert again.var == pytest.approx(dist.var, rel=1e-12)


@pytest.mark.parametrize("params", CASES.values(), ids=CASES.keys())
def test_scaling_multiplies_mean_and_sd(params: dict) -> None:
    dist = make_distribution(params)
    slow = dist.scaled(1.5)
    assert slow.mean == pytest.approx(1.5 * dist.mean, rel=1e-9)
    assert slow.var == pytest.approx(2.25 * dist.var, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("name", ["lognormal-median", "gamma", "weibull", "normal-bounded",
                                  "normal-far-tail", "exponential", "exgauss", "triangular",
                                  "uniform"])
def test_quantile_inverts_cdf_and_matches_the_sample(name: str) -> None:
    dist = make_distribution(CASES[name])
    x = dist.sample_many(np.random.default_rng(3), 100_000)
    for q in (0.05, 0.5, 0.95):
        v = dist.quantile(q)
        assert dist.cdf(v) == pytest.approx(q, abs=1e-6)
        # Empirical CDF at the quantile: binomial standard error sqrt(q(1-q)/n), 5 of them.
        assert np.mean(x <= v) == pytest.approx(q, abs=5 * math.sqrt(q * (1 - q) / x.size))


def test_lognormal_median_form_has_that_median() -> None:
    assert LogNormal.from_median(60, 0.6).quantile(0.5) == pytest.approx(60.0)


def test_same_seed_gives_the_same_samples() -> None:
    dist = make_distribution(CASES["exgauss"])
    a = dist.sample_many(np.random.default_rng(5), 10)
    b = dist.sample_many(np.random.default_rng(5), 10)
    assert np.array_equal(a, b)


def test_a_bare_number_is_a_constant() -> None:
    assert make_distribution(3).sample(np.random.default_rng(0)) == 3.0


BAD = {
    "negative-sigma": ({"kind": "lognormal", "median": 60, "sigma": -1}, "sigma",
                       r"must be > 0, got -1"),
    "zero-median": ({"kind": "lognormal", "median": 0, "sigma": 1}, "median", r"must be > 0"),
    "negative-scale": ({"kind": "gamma", "shape": 2, "scale": -3}, "scale", r"must be > 0"),
    "unknown-kind": ({"kind": "cauchy", "x": 1}, "kind", r"unknown distribution 'cauchy'"),
    "typo-in-parameter": ({"kind": "lognormal", "median": 60, "sigam": 1}, "sigam",
                          r"not a parameter of a lognormal"),
    "missing-parameter": ({"kind": "exgauss", "mu": 1, "sigma": 1}, "tau", r"is required"),
    "mode-outside": ({"kind": "triangular", "low": 1, "mode": 9, "high": 5}, "mode",
                     r"within \[low, high\]"),
    "high-below-low": ({"kind": "uniform", "low": 5, "high": 1}, "high", r"must be finite and > low"),
    "no-mass": ({"kind": "normal", "mean": 0, "sd": 1, "low": 50}, "low", r"no probability mass"),
    "empty-data": ({"kind": "empirical", "values": []}, "values", r"at least one"),
    "text-parameter": ({"kind": "exponential", "mean": "ten"}, "mean", r"must be a number"),
    "nan": ({"kind": "exponential", "mean": float("nan")}, "mean", r"nan"),
    # a misspelt name is named, not reported as the parameter it was meant to be
    "lognormal-typo": ({"kind": "lognormal", "medain": 60, "sigma": 0.6}, "medain",
                       r"not a parameter of a lognormal.*did you mean median\?"),
}


@pytest.mark.parametrize(("params", "param", "message"), BAD.values(), ids=BAD.keys())
def test_bad_parameters_raise_a_user_model_error_naming_the_parameter(
        params: dict, param: str, message: str) -> None:
    with pytest.raises(UserModelError, match=message) as info:
        make_distribution(params)
    assert isinstance(info.value, ParameterError)
    assert info.value.param == param


def test_unknown_kind_lists_the_known_kinds() -> None:
    with pytest.raises(UserModelError, match=r"use one of: constant, empirical, exgauss"):
        make_distribution({"kind": "cauchy"})


BPSIM = {
    "ConstantParameter": (("value", 4.0),),
    "NormalDistribution": (("mean", 30.0), ("standardDeviation", 5.0)),
    "LogNormalDistribution": (("mean", 10.0), ("standardDeviation", 4.0)),
    "UniformDistribution": (("min", 2.0), ("max", 4.0)),
    "ExponentialDistribution": (("mean", 9.0),),
    "TriangularDistribution": (("min", 1.0), ("mode", 2.0), ("max", 6.0)),
    "GammaDistribution": (("shape", 2.0), ("scale", 3.0)),
    "WeibullDistribution": (("shape", 2.0), ("scale", 3.0)),
    "TruncatedNormalDistribution": (("mean", 30.0), ("standardDeviation", 5.0), ("min", 25.0),
                                    ("max", 50.0)),
    "lognormal": (("median", 60.0), ("sigma", 0.6)),
    "exgauss": (("mu", 1.0), ("sigma", 0.1), ("tau", 0.5)),
}
EXPECTED_MEANS = {
    "ConstantParameter": 4.0, "NormalDistribution": 30.0, "LogNormalDistribution": 10.0,
    "UniformDistribution": 3.0, "ExponentialDistribution": 9.0, "TriangularDistribution": 3.0,
    "GammaDistribution": 6.0, "WeibullDistribution": 3.0 * math.gamma(1.5),
    "lognormal": 60.0 * math.exp(0.18), "exgauss": 1.5,
}


@pytest.mark.parametrize(("kind", "parameters"), BPSIM.items(), ids=BPSIM.keys())
def test_spec_distributions_adapt_with_bpsim_parameter_names(kind: str, parameters: tuple
                                                             ) -> None:
    dist = from_model(ModelDistribution(kind=kind, parameters=parameters))
    if kind in EXPECTED_MEANS:
        # NormalDistribution is truncated at 0; at mean 30, sd 5 that changes nothing visible.
        assert dist.mean == pytest.approx(EXPECTED_MEANS[kind], rel=1e-6)
    else:
        assert 30.0 < dist.mean < 50.0


def test_bpsim_lognormal_keeps_the_standard_deviation_of_the_variable() -> None:
    dist = from_model(ModelDistribution(kind="LogNormalDistribution",
                                        parameters=(("mean", 10.0), ("standardDeviation", 4.0))))
    assert dist.sd == pytest.approx(4.0)
