"""The response-time presets against the study and the data they come from (issue 19;
docs/presets.md, "Response times by age").

``reaction-time-young``, ``reaction-time-older`` and ``reaction-time-by-age`` hold ex-Gaussian
parameters fitted (with opspec's own fitter) to the released trial-level data of

    Ribeiro, M., & Castelo-Branco, M. (2022). Slow fluctuations in ongoing brain activity
    decrease in amplitude with ageing yet their impact on task-related evoked responses is
    dissociable from behavior. eLife, 11, e75722. doi:10.7554/eLife.75722

(cued auditory go/no-go task; young N = 36, 23 +/- 3 years; older N = 39, 60 +/- 5 years).
The paper publishes no ex-Gaussian table, so the chain is checked link by link:

1. ``PAPER``: values typed from the article (Results, "Behavioral variability is increased in
   older adults"; Materials and methods, "Participants").
2. ``DATA``: the group summaries of the extraction from the released data (34 of the 36 young
   and 37 of the 39 older people have a behavioural file; the authors estimated the other
   four from EEG triggers). Tests check that these summaries reproduce the paper's t
   statistics and error shares - a wrong extraction (groups swapped, slow trials dropped,
   error trials kept) would not.
3. The presets: their numbers must be the ``DATA`` means, their ex-Gaussian mean mu + tau the
   group's mean RT, and the population preset must draw people with the measured spread.

``test_the_summaries_are_recomputed_from_the_released_data`` redoes step 2 from the data when
``OPSPEC_RIBEIRO2022_DATA`` names a local copy of the folder
``Figure1/data_with_task_parameters_for_RT_analyses`` of
github.com/CIBIT-UC/2021_Ribeiro_BrainVariability_Aging (not shipped with opspec).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy import stats

from opspec.usermodels import load_user_model
from opspec.usermodels.distributions import ExGaussian

GROUPS = ("young", "older")

# 1. The article. t(73) and p of independent-samples t-tests, young against older, of each
# person's median RT, across-trial RT SD and coefficient of variation; shares of people with
# at least one missed go trial / at least one response to the warning cue.
PAPER = {
    "n": {"young": 36, "older": 39},
    "age": {"young": (23, 3), "older": (60, 5)},
    "t": {"median": -1.84, "sd": -2.53, "cv": -1.57},
    "p": {"median": 0.070, "sd": 0.013, "cv": 0.120},
    "missed_share": {"young": 0.22, "older": 0.38},
    "cue_share": {"young": 0.14, "older": 0.36},
}

# 2. The released data, extracted with the authors' rules (script a1_..._gng_withSlowTrials.m)
# and fitted per person with opspec.usermodels.families.fit_family("exgauss"): n people;
# (mean, sd) across people of each person's median RT, mean RT, RT SD, CV and fitted
# mu / sigma / tau (seconds); people with >= 1 miss / >= 1 cue response; Spearman rank
# correlations across people of (mu, sigma), (mu, tau), (sigma, tau).
DATA = {
    "young": {"n": 34, "median": (0.39429, 0.05446), "mean": (0.41041, 0.05300),
              "sd": (0.09006, 0.02023), "cv": (0.22012, 0.04468),
              "mu": (0.3308, 0.0556), "sigma": (0.0351, 0.0206), "tau": (0.0796, 0.0214),
              "missed": 7, "cue": 5, "spearman": (0.77, -0.25, -0.32)},
    "older": {"n": 37, "median": (0.41537, 0.06722), "mean": (0.43032, 0.05761),
              "sd": (0.10196, 0.02212), "cv": (0.23845, 0.05145),
              "mu": (0.3444, 0.0765), "sigma": (0.0445, 0.0340), "tau": (0.0859, 0.0356),
              "missed": 14, "cue": 13, "spearman": (0.91, -0.70, -0.72)},
}

PRESET = {"young": "reaction-time-young", "older": "reaction-time-older"}


def _t(measure: str) -> Any:
    (m1, s1), (m2, s2) = DATA["young"][measure], DATA["older"][measure]
    return stats.ttest_ind_from_stats(m1, s1, DATA["young"]["n"], m2, s2, DATA["older"]["n"],
                                      equal_var=True)


@pytest.mark.parametrize("measure", ["median", "sd", "cv"])
def test_the_extraction_reproduces_the_papers_t_tests(measure: str) -> None:
    """Student's t of the data's group summaries against the article's t(73). 4 of the 75
    people (their RTs estimated by the authors from EEG triggers) are not in the release,
    which moves t by a few tenths; a swapped group flips the sign, and dropping the slow
    trials or keeping error trials changes SD and CV by far more."""
    result = _t(measure)
    assert result.statistic == pytest.approx(PAPER["t"][measure], abs=0.5)
    assert (result.pvalue < 0.05) == (PAPER["p"][measure] < 0.05)


def test_the_extraction_reproduces_the_papers_error_shares() -> None:
    for group in GROUPS:
        n = DATA[group]["n"]
        assert n == PAPER["n"][group] - 2          # two people per group lack a file
        assert DATA[group]["missed"] / n == pytest.approx(PAPER["missed_share"][group],
                                                          abs=0.02)
        assert DATA[group]["cue"] / n == pytest.approx(PAPER["cue_share"][group], abs=0.02)


@pytest.mark.parametrize("group", GROUPS)
def test_each_preset_is_the_groups_mean_fit_and_its_mean_the_groups_mean_rt(group: str
                                                                            ) -> None:
    duration = load_user_model(PRESET[group]).default.duration
    assert isinstance(duration, ExGaussian)
    for name in ("mu", "sigma", "tau"):
        assert getattr(duration, name) == pytest.approx(DATA[group][name][0], abs=5e-5)
    # the ex-Gaussian's mean is mu + tau: the group's mean RT (the maximum-likelihood fits
    # keep each person's mean; averaging keeps the group's)
    assert duration.mean == pytest.approx(duration.mu + duration.tau, abs=1e-12)
    assert duration.mean == pytest.approx(DATA[group]["mean"][0], abs=0.0005)
    # and as sampled
    draws = duration.sample_many(np.random.default_rng(19), 100_000)
    assert float(draws.mean()) == pytest.approx(duration.mean, abs=0.001)


def test_the_older_preset_is_slower_and_more_variable_as_published() -> None:
    """The article: older people slower on average (n.s.), with a larger across-trial SD
    (p = .013). The typical older person's ex-Gaussian has a larger mean and SD
    (sqrt(sigma^2 + tau^2)), and each SD is within 7 % of the group's mean RT SD."""
    young = load_user_model(PRESET["young"]).default.duration
    older = load_user_model(PRESET["older"]).default.duration
    assert isinstance(young, ExGaussian) and isinstance(older, ExGaussian)

    def sd(d: ExGaussian) -> float:
        return math.hypot(d.sigma, d.tau)

    assert older.mean > young.mean and sd(older) > sd(young)
    for group, d in (("young", young), ("older", older)):
        assert sd(d) == pytest.approx(DATA[group]["sd"][0], rel=0.07)
    # the older group's slowing of this prepared response is small: well under the Brinley
    # slope of older-adults (x 1.5) and of Cerella et al. 1980 (x 1.36)
    assert 1.0 < older.mean / young.mean < 1.1


def test_the_population_draws_people_with_the_measured_spread() -> None:
    model = load_user_model("reaction-time-by-age")
    people = [model.individual(2010, user) for user in range(4000)]
    young_share = sum(p.subgroup == "young" for p in people) / len(people)
    assert young_share == pytest.approx(PAPER["n"]["young"] / 75, abs=3 * math.sqrt(
        0.25 / len(people)))
    for group in GROUPS:
        drawn = np.array([[p.parameters[f"defaults.duration.{k}"] for k in ("mu", "sigma",
                                                                              "tau")]
                          for p in people if p.subgroup == group])
        n = len(drawn)
        for column, name in enumerate(("mu", "sigma", "tau")):
            mean, sd = DATA[group][name]
            assert float(drawn[:, column].mean()) == pytest.approx(mean, abs=4 * sd
                                                                    / math.sqrt(n))
            assert float(drawn[:, column].std(ddof=1)) == pytest.approx(sd, rel=0.1)
        assert np.all(drawn > 0)
        rho = stats.spearmanr(drawn).statistic
        for (i, j), expected in zip(((0, 1), (0, 2), (1, 2)), DATA[group]["spearman"]):
            assert rho[i, j] == pytest.approx(expected, abs=0.06)
        # each person's own model is an ex-Gaussian with the drawn parameters
        person = next(p for p in people if p.subgroup == group)
        duration = person.model.default.duration
        assert isinstance(duration, ExGaussian)
        assert duration.mu == person.parameters["defaults.duration.mu"]


# ------------------------------------------------------------- step 2, from the data itself

_YOUNG = (4, 6, 9, 10, 13, 15, 16, 25, 26, 28, 31, 33, 34, 36, 42, 44, 45, 46, 50, 51, 53,
          54, 56, 59, 62, 66, 68, 72, 74, 76, 78, 80, 81, 82, 84, 85)
_OLDER = (7, 8, 11, 12, 14, 17, 19, 20, 21, 22, 23, 32, 35, 37, 38, 41, 43, 47, 48, 49, 52,
          55, 57, 58, 60, 61, 63, 64, 65, 67, 69, 70, 71, 73, 75, 77, 79, 83, 86)


def _correct_go_rts(folder: Path) -> tuple[np.ndarray, int, int]:
    """One person's correct go-trial RTs of runs G1 and G2 by the authors' rules (script
    a1): drop responses to the cue, misses (RT -1), responses to blanks or no-go tones and
    the trial after each, and the trial after a slow (> 0.7 s) response; plus the person's
    numbers of misses and cue responses."""
    from scipy.io import loadmat

    def load(run: str, name: str) -> np.ndarray:
        return np.asarray(loadmat(folder / run / f"{name}.mat")[name])

    def answered(cells: np.ndarray) -> np.ndarray:
        return np.array([i for i, c in enumerate(cells.ravel()) if np.asarray(c).size], int)

    kept, misses, cues = [], 0, 0
    for run in ("G1", "G2"):
        rt = load(run, "imperative_times").astype(float)
        rt = (rt[:, 0] if rt.ndim == 2 and min(rt.shape) > 1 else rt).ravel()
        order = load(run, "stimuli_order").ravel()
        cue = answered(load(run, "anticipatory_keys"))
        missed = np.flatnonzero((rt == -1) & (order[:rt.size] == 1))
        blank, nogo = answered(load(run, "blank_keys")), answered(load(run, "nogo_keys"))
        slow = np.flatnonzero(rt > 0.7)
        bad = np.concatenate([cue, cue + 1, slow + 1, missed, missed + 1, blank, blank + 1,
                              nogo, nogo + 1])
        kept.append(rt[np.setdiff1d(np.flatnonzero(order == 1), bad)])
        misses += len(missed)
        cues += len(cue)
    return np.concatenate(kept), misses, cues


@pytest.mark.skipif(not os.environ.get("OPSPEC_RIBEIRO2022_DATA"),
                    reason="set OPSPEC_RIBEIRO2022_DATA to the released data folder "
                           "(Figure1/data_with_task_parameters_for_RT_analyses)")
def test_the_summaries_are_recomputed_from_the_released_data() -> None:
    from opspec.usermodels.families import fit_family

    root = Path(os.environ["OPSPEC_RIBEIRO2022_DATA"])
    for group, ids in (("young", _YOUNG), ("older", _OLDER)):
        rows, missed, cued = [], 0, 0
        for person in ids:
            if not (root / f"AB{person}").is_dir():
                continue
            rt, misses, cues = _correct_go_rts(root / f"AB{person}")
            fit = fit_family("exgauss", rt)
            assert fit is not None and isinstance(fit.distribution, ExGaussian)
            d = fit.distribution
            sd = float(rt.std(ddof=1))
            rows.append((np.median(rt), rt.mean(), sd, sd / rt.mean(), d.mu, d.sigma, d.tau))
            missed += misses > 0
            cued += cues > 0
        table = np.array(rows)
        expected = DATA[group]
        assert len(table) == expected["n"]
        assert (missed, cued) == (expected["missed"], expected["cue"])
        for column, name in enumerate(("median", "mean", "sd", "cv", "mu", "sigma", "tau")):
            mean, sd = expected[name]
            assert float(table[:, column].mean()) == pytest.approx(mean, abs=6e-5)
            assert float(table[:, column].std(ddof=1)) == pytest.approx(sd, abs=6e-5)
        rho = stats.spearmanr(table[:, 4:7]).statistic
        assert [round(float(rho[i, j]), 2) for i, j in ((0, 1), (0, 2), (1, 2))] == list(
            expected["spearman"])
