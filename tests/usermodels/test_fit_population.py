"""`opspec fit` on a population (issue 19): gamma and Weibull beside lognormal and
ex-Gaussian, chosen by AIC/BIC with the comparison shown; the time a wrong choice costs
apart from the choice's own duration; and how much users differ, per user then pooled.

References nobody here wrote: the asymptotic standard errors of the maximum-likelihood
estimates come from the Fisher information of each family (gamma: I = [[psi1(k), 1/theta],
[1/theta, k/theta^2]]; Weibull: I = [[((1-g)^2 + pi^2/6)/c^2, -(1-g)/lambda],
[-(1-g)/lambda, c^2/lambda^2]] per observation, g the Euler-Mascheroni constant), and the
between-user spreads are the parameters the simulated users were drawn with.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import special, stats

from opspec.cli import main
from opspec.usermodels import load_user_model
from opspec.usermodels.distributions import ExGaussian, Gamma, LogNormal, Weibull
from opspec.usermodels.families import choose, fit_families, fit_family
from opspec.usermodels.fitting import fit_traces

EULER = 0.5772156649015329


def _se(information: np.ndarray, n: int) -> np.ndarray:
    return np.sqrt(np.diag(np.linalg.inv(information)) / n)


@pytest.mark.parametrize("shape,scale,seed", [(2.0, 15.0, 1), (5.0, 4.0, 2), (0.8, 30.0, 3)])
def test_gamma_parameters_are_recovered_within_sampling_error(shape, scale, seed) -> None:
    n = 3000
    x = Gamma(shape, scale).sample_many(np.random.default_rng(seed), n)
    fit = fit_family("gamma", x)
    assert fit is not None and isinstance(fit.distribution, Gamma)
    info = np.array([[special.polygamma(1, shape), 1 / scale], [1 / scale, shape / scale**2]])
    se_shape, se_scale = _se(info, n)
    assert fit.distribution.shape == pytest.approx(shape, abs=4 * se_shape)
    assert fit.distribution.scale == pytest.approx(scale, abs=4 * se_scale)


@pytest.mark.parametrize("shape,scale,seed", [(1.5, 60.0, 4), (3.0, 20.0, 5), (0.9, 8.0, 6)])
def test_weibull_parameters_are_recovered_within_sampling_error(shape, scale, seed) -> None:
    n = 3000
    x = Weibull(shape, scale).sample_many(np.random.default_rng(seed), n)
    fit = fit_family("weibull", x)
    assert fit is not None and isinstance(fit.distribution, Weibull)
    info = np.array([[((1 - EULER) ** 2 + math.pi**2 / 6) / shape**2, -(1 - EULER) / scale],
                     [-(1 - EULER) / scale, shape**2 / scale**2]])
    se_shape, se_scale = _se(info, n)
    assert fit.distribution.shape == pytest.approx(shape, abs=4 * se_shape)
    assert fit.distribution.scale == pytest.approx(scale, abs=4 * se_scale)


def test_the_log_likelihood_is_scipys_at_the_fitted_parameters() -> None:
    x = Weibull(1.7, 40.0).sample_many(np.random.default_rng(7), 500)
    fits = {f.family: f for f in fit_families(x)}
    w = fits["weibull"]
    assert w.log_likelihood == pytest.approx(
        stats.weibull_min.logpdf(x, w.distribution.shape, scale=w.distribution.scale).sum())
    assert w.aic == pytest.approx(4 - 2 * w.log_likelihood)
    assert w.bic == pytest.approx(2 * math.log(500) - 2 * w.log_likelihood)
    assert fits["exgauss"].parameters == 3


GENERATORS = {
    "lognormal": LogNormal(math.log(60), 0.6),
    "gamma": Gamma(2.0, 15.0),
    "weibull": Weibull(3.5, 40.0),
    "exgauss": ExGaussian(2.0, 0.3, 1.5),
}


@pytest.mark.parametrize("criterion", ["aic", "bic"])
@pytest.mark.parametrize("family", list(GENERATORS))
@pytest.mark.parametrize("seed", [11, 12, 13])
def test_the_generating_family_wins_at_2000_observations(family, criterion, seed) -> None:
    """At n = 2000 these four shapes are far apart in likelihood (differences of tens of
    AIC units), so the criterion must pick the family the data came from."""
    x = GENERATORS[family].sample_many(np.random.default_rng(seed), 2000)
    assert choose(fit_families(x), criterion).family == family


def test_zero_durations_leave_only_the_ex_gaussian() -> None:
    x = np.concatenate([np.zeros(5), ExGaussian(2.0, 0.5, 1.0).sample_many(
        np.random.default_rng(1), 300)])
    assert [f.family for f in fit_families(x)] == ["exgauss"]


# ---------------------------------------------------------------- traces of a population
def _event(seq: int, time: float, kind: str, activity: str, instance: int,
           **data: object) -> str:
    return json.dumps({"seq": seq, "time": time, "kind": kind, "process": "p",
                       "instance": instance, "activity": activity, "lane": "user",
                       "participant": "user", "data": data})


def write_population(path: Path, users: list[dict[str, list]]) -> Path:
    """One JSON Lines trace, one run per user: each user has ``durations`` of activity
    ``walk``, ``heard`` (True/False per prompt ``hear``) and ``picks`` of choice ``choose``
    as (alternative, seconds)."""
    lines = [json.dumps({"format": "opspec-trace", "version": 1})]
    seq = 0
    for user in users:
        seq += 1
        lines.append(json.dumps({"seq": seq, "time": 0, "kind": "run.started", "data": {}}))
        t, instance = 0.0, 0
        for d in user.get("durations", []):
            instance += 1
            lines.append(_event(seq := seq + 1, t, "activity.offered", "walk", instance))
            lines.append(_event(seq := seq + 1, t + d, "activity.completed", "walk", instance))
            t += d + 100
        for heard in user.get("heard", []):
            instance += 1
            lines.append(_event(seq := seq + 1, t, "activity.offered", "hear", instance))
            kind = "activity.completed" if heard else "activity.omitted"
            extra = {} if heard else {"reason": "not heard"}
            lines.append(_event(seq := seq + 1, t, kind, "hear", instance, **extra))
            t += 100
        for pick, seconds in user.get("picks", []):
            instance += 1
            lines.append(_event(seq := seq + 1, t, "activity.offered", "choose", instance,
                                choices=["right", "wrong"]))
            lines.append(_event(seq := seq + 1, t + seconds, "activity.completed", "choose",
                                instance, choice=pick))
            if pick == "wrong":       # the lane offers the choice again, picked right
                lines.append(_event(seq := seq + 1, t + seconds, "activity.offered", "choose",
                                    instance, choices=["right", "wrong"]))
                lines.append(_event(seq := seq + 1, t + seconds + 1.0, "activity.completed",
                                    "choose", instance, choice="right"))
            t += 100
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_between_user_spread_of_durations_is_recovered(tmp_path: Path) -> None:
    """300 users whose walking scale differs by a lognormal factor with sigma 0.15 (each
    user's walk: lognormal, median 60 s x factor, sigma 0.6; 10 walks each). With 10 walks
    a user's mean has a sampling sd of about 0.21 on the log scale, more than the spread
    between users: the naive sd of user means (about 0.26) overstates it."""
    rng = np.random.default_rng(21)
    tau = 0.15
    users = [{"durations": list(np.exp(rng.normal(math.log(60) + rng.normal(0, tau), 0.6,
                                                   10)))} for _ in range(300)]
    fit = next(f for f in fit_traces([write_population(tmp_path / "p.jsonl", users)]).fits
               if f.activity == "walk")
    spread = fit.duration_spread
    assert spread is not None and spread.users == 300
    low, high = spread.between_sd_ci
    assert low < tau < high
    assert spread.between_sd == pytest.approx(tau, abs=0.05)
    assert spread.observed_sd > 0.22      # what per-user estimates alone would have said


def test_identical_users_show_no_between_user_spread(tmp_path: Path) -> None:
    rng = np.random.default_rng(22)
    users = [{"durations": list(np.exp(rng.normal(math.log(60), 0.6, 40))),
              "heard": list(rng.random(80) < 0.85)} for _ in range(100)]
    result = fit_traces([write_population(tmp_path / "p.jsonl", users)])
    walk = next(f for f in result.fits if f.activity == "walk").duration_spread
    hear = next(f for f in result.fits if f.activity == "hear").omission_spread
    assert walk is not None and walk.between_sd_ci[0] == 0.0 and walk.between_sd < 0.05
    assert hear is not None and hear.between_sd_ci[0] == 0.0
    assert hear.homogeneity_p > 0.01


def test_between_user_spread_of_omissions_is_recovered(tmp_path: Path) -> None:
    """200 users, each missing prompts with their own p ~ Beta(2, 18): mean 0.1, between-user
    sd sqrt(ab / ((a+b)^2 (a+b+1))) = 0.0655; 80 prompts each."""
    rng = np.random.default_rng(23)
    a, b = 2.0, 18.0
    sd = math.sqrt(a * b / ((a + b) ** 2 * (a + b + 1)))
    users = [{"heard": list(rng.random(80) >= rng.beta(a, b))} for _ in range(200)]
    fit = next(f for f in fit_traces([write_population(tmp_path / "p.jsonl", users)]).fits
               if f.activity == "hear")
    spread = fit.omission_spread
    assert spread is not None
    assert spread.mean == pytest.approx(0.1, abs=0.01)
    low, high = spread.between_sd_ci
    assert low < sd < high
    assert spread.homogeneity_p < 1e-6
    fa, fb = spread.beta
    assert fa / (fa + fb) == pytest.approx(0.1, abs=0.01)


def test_the_time_a_wrong_choice_costs_is_separated_from_the_choice(tmp_path: Path) -> None:
    """Deciding takes lognormal(median 2 s, sigma 0.3); a wrong pick costs 8 s more
    (pressing the wrong button and noticing). The choice's duration is the decision only,
    and the wrong alternative gets the 8 s."""
    rng = np.random.default_rng(24)
    users = []
    for _ in range(20):
        picks = []
        for _ in range(100):
            decide = float(np.exp(rng.normal(math.log(2.0), 0.3)))
            picks.append(("wrong", decide + 8.0) if rng.random() < 0.1 else ("right", decide))
        users.append({"picks": picks})
    result = fit_traces([write_population(tmp_path / "p.jsonl", users)])
    fit = next(f for f in result.fits if f.activity == "choose")
    loss = fit.wrong_choice
    assert loss is not None and loss.alternatives == ("wrong",)
    assert loss.ci[0] < 8.0 < loss.ci[1]
    choose_model = result.model.activities["choose"]
    assert choose_model.intended == "right"
    # the choice's own duration is the decision's: median 2 s (right picks after a wrong
    # one take 1 s and pull it down a little), not the mixture with the 8 s losses
    assert 1.7 < choose_model.duration.quantile(0.5) < 2.2
    assert result.model.activities["wrong"].duration.mean == pytest.approx(8.0, abs=0.5)


def test_cli_shows_the_family_table_and_json(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    rng = np.random.default_rng(25)
    users = [{"durations": list(Gamma(3.0, 10.0).sample_many(rng, 60))} for _ in range(10)]
    trace = write_population(tmp_path / "g.jsonl", users)
    out = tmp_path / "g.users.toml"
    assert main(["fit", str(trace), "-o", str(out), "--criterion", "bic"]) == 0
    text = capsys.readouterr().out
    assert "gamma chosen by BIC" in text and "<- chosen" in text
    for family in ("lognormal", "gamma", "weibull", "exgauss"):
        assert f"  {family} " in text
    assert "gamma chosen by BIC" in out.read_text()
    assert load_user_model(out).activities["walk"].duration.kind == "gamma"
    assert main(["fit", str(trace), "-o", str(out), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    walk = doc["activities"]["walk"]
    assert walk["chosen"] == "gamma" and walk["criterion"] == "aic"
    assert {f["family"] for f in walk["families"]} == {"lognormal", "gamma", "weibull",
                                                        "exgauss"}
    assert all("aic" in f and "bic" in f for f in walk["families"])
    spread = walk["between_users"]["duration"]
    assert spread["users"] == 10 and spread["per_user_distribution"]["kind"] == "lognormal"


def test_cli_refuses_json_to_standard_output_twice(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    trace = write_population(tmp_path / "g.jsonl", [{"durations": [1.0, 2.0, 3.0]}])
    assert main(["fit", str(trace), "-o", "-", "--json"]) == 2
    assert "both want standard output" in capsys.readouterr().err


def test_the_fitted_file_draws_each_user_from_the_estimated_spread(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Users who differ (walk median by a lognormal factor, sigma 0.3; omission p ~ Beta(2,
    18)) give a fitted file with [vary] tables: loaded back, it is a population whose
    simulated people differ as much as the estimate says, and whose walks pooled over
    people keep the observed spread (one person's sigma is the within-user part)."""
    rng = np.random.default_rng(26)
    users = [{"durations": list(np.exp(rng.normal(math.log(60) + rng.normal(0, 0.3), 0.6,
                                                   20))),
              "heard": list(rng.random(60) >= rng.beta(2, 18))} for _ in range(150)]
    out = tmp_path / "people.users.toml"
    assert main(["fit", str(write_population(tmp_path / "p.jsonl", users)), "-o",
                 str(out)]) == 0
    capsys.readouterr()
    model = load_user_model(out)
    population = model.population
    assert population is not None
    people = [population.draw(0, u) for u in range(2000)]
    medians = np.array([p.parameters["activities.walk.duration.median"] for p in people])
    assert np.std(np.log(medians)) == pytest.approx(0.3, abs=0.06)
    misses = np.array([p.parameters["activities.hear.omission.probability"] for p in people])
    assert misses.mean() == pytest.approx(0.1, abs=0.015)
    assert misses.std() == pytest.approx(0.0655, abs=0.02)
    own = model.activities["walk"].duration
    assert isinstance(own, LogNormal) and own.sigma == pytest.approx(0.6, abs=0.04)
